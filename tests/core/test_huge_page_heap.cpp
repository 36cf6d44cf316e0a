#include <catch2/catch.hpp>

#include "core/huge_page_heap.hpp"

using namespace febemesh;

TEST_CASE("the huge-page tunable is added to GLIBC_TUNABLES, once", "[huge_pages]") {
  CHECK(tunables_with_huge_page_heap(nullptr) == "glibc.malloc.hugetlb=1");
  CHECK(tunables_with_huge_page_heap("") == "glibc.malloc.hugetlb=1");
  CHECK(tunables_with_huge_page_heap("glibc.malloc.check=3") == "glibc.malloc.check=3:glibc.malloc.hugetlb=1");
  // Already set, to any value, anywhere in the list: left alone (and no second exec).
  CHECK_FALSE(tunables_with_huge_page_heap("glibc.malloc.hugetlb=1"));
  CHECK_FALSE(tunables_with_huge_page_heap("glibc.malloc.hugetlb=0"));
  CHECK_FALSE(tunables_with_huge_page_heap("glibc.malloc.check=3:glibc.malloc.hugetlb=2"));
  // A name that only starts like it is another tunable.
  CHECK(tunables_with_huge_page_heap("glibc.malloc.hugetlbx=1") == "glibc.malloc.hugetlbx=1:glibc.malloc.hugetlb=1");
}
