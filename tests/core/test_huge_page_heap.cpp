#include <catch2/catch.hpp>

#include <string>

#include "core/huge_page_heap.hpp"

using namespace febemesh;

TEST_CASE("the huge-page tunable is added to GLIBC_TUNABLES, once", "[huge_pages]") {
  // With it, one malloc arena for all threads (unless the caller chose a number).
  const std::string both = "glibc.malloc.arena_max=1:glibc.malloc.hugetlb=1";
  CHECK(tunables_with_huge_page_heap(nullptr) == both);
  CHECK(tunables_with_huge_page_heap("") == both);
  CHECK(tunables_with_huge_page_heap("glibc.malloc.check=3") == "glibc.malloc.check=3:" + both);
  CHECK(tunables_with_huge_page_heap("glibc.malloc.arena_max=4") == "glibc.malloc.arena_max=4:glibc.malloc.hugetlb=1");
  // Already set, to any value, anywhere in the list: left alone (and no second exec).
  CHECK_FALSE(tunables_with_huge_page_heap("glibc.malloc.hugetlb=1"));
  CHECK_FALSE(tunables_with_huge_page_heap("glibc.malloc.hugetlb=0"));
  CHECK_FALSE(tunables_with_huge_page_heap("glibc.malloc.check=3:glibc.malloc.hugetlb=2"));
  // A name that only starts like it is another tunable.
  CHECK(tunables_with_huge_page_heap("glibc.malloc.hugetlbx=1") == "glibc.malloc.hugetlbx=1:" + both);
  CHECK(tunables_with_huge_page_heap("glibc.malloc.arena_maxx=2") == "glibc.malloc.arena_maxx=2:" + both);
}

TEST_CASE("a tunable is set when its name starts an entry of GLIBC_TUNABLES", "[huge_pages]") {
  CHECK_FALSE(tunable_is_set(nullptr, "glibc.malloc.arena_max"));
  CHECK_FALSE(tunable_is_set("", "glibc.malloc.arena_max"));
  CHECK(tunable_is_set("glibc.malloc.arena_max=4", "glibc.malloc.arena_max"));
  CHECK(tunable_is_set("glibc.malloc.check=3:glibc.malloc.arena_max=2", "glibc.malloc.arena_max"));
  CHECK_FALSE(tunable_is_set("glibc.malloc.arena_maxx=2", "glibc.malloc.arena_max"));
  CHECK_FALSE(tunable_is_set("xglibc.malloc.arena_max=2", "glibc.malloc.arena_max"));
  CHECK_FALSE(tunable_is_set("glibc.malloc.arena_max", "glibc.malloc.arena_max"));  // no value: not an entry
}

