#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include "core/huge_page_heap.hpp"
#include "core/huge_pages.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/wait.h>
#endif

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


// mallinfo2 and mallopt are glibc's; AddressSanitizer brings its own allocator.
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
TEST_CASE("set_up_malloc's mapping rule, in a fresh process", "[.][malloc_child]") {
  // Run by the test below in a process of its own: in this one the heap may hold free room of
  // that size from earlier tests, which malloc takes before it maps anything. A spec of
  // exclusions only ("~[property]") runs hidden tests too: then nothing.
  if (!std::getenv("FEBEMESH_MALLOC_CHILD")) return;
  set_up_malloc();
  const auto mapped = [] { return mallinfo2().hblkhd; };  // bytes in blocks mapped on their own
  const std::size_t before = mapped();
  // Twice: glibc's own threshold would rise to the first block's size when it is freed, and
  // the second would come from the heap, whose freed middle stays resident.
  for (int round = 0; round < 2; ++round) {
    void* volatile block = std::malloc(own_mapping_bytes);
    REQUIRE(block != nullptr);
    CHECK(mapped() >= before + own_mapping_bytes);
    std::free(block);
    CHECK(mapped() == before);
  }
  // Under the threshold: from the heap.
  void* volatile small = std::malloc(own_mapping_bytes / 2);
  REQUIRE(small != nullptr);
  CHECK(mapped() == before);
  std::free(small);
}

TEST_CASE("set_up_malloc maps every large block on its own and gives it back when freed", "[huge_pages]") {
  if (test::sanitized()) return;  // the sanitizer's allocator, whichever compiler built it
  if (tunable_is_set(std::getenv("GLIBC_TUNABLES"), "glibc.malloc.mmap_threshold")) {
    WARN("GLIBC_TUNABLES sets glibc.malloc.mmap_threshold: set_up_malloc leaves it");
    return;
  }
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const int status = std::system(("FEBEMESH_MALLOC_CHILD=1 '" + self + "' '[malloc_child]' > /dev/null 2>&1").c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
}
#endif

TEST_CASE("reserve_huge keeps what a vector holds, on any thread count", "[huge_pages]") {
  // The fresh room is populated and, on several threads, first written a byte a page: never
  // the elements moved into it. 3 x 10^6 ints (12 MB, over the 4 MiB of the threaded touch).
  for (const int n_threads : {1, 2, 3}) {
    std::vector<std::int32_t> v(1'000'003);
    std::iota(v.begin(), v.end(), 7);
    reserve_huge(v, 3'000'000, n_threads);
    REQUIRE(v.capacity() >= 3'000'000);
    REQUIRE(v.size() == 1'000'003);
    bool intact = true;
    for (std::size_t i = 0; i < v.size(); ++i) intact = intact && v[i] == static_cast<std::int32_t>(i + 7);
    CHECK(intact);
    v.resize(3'000'000);  // the new elements value-initialized over the touched bytes
    CHECK(v[1'000'003] == 0);
    CHECK(v.back() == 0);
    CHECK(std::all_of(v.begin() + 1'000'003, v.end(), [](std::int32_t x) { return x == 0; }));
    // Room already there: nothing moves, nothing is written.
    const std::int32_t* at = v.data();
    v[5] = -1;
    reserve_huge(v, 2'000'000, n_threads);
    CHECK(v.data() == at);
    CHECK(v[5] == -1);
  }
  // Empty and tiny requests.
  std::vector<double> e;
  reserve_huge(e, 0, 2);
  CHECK(e.empty());
  reserve_huge(e, 3, 2);
  CHECK(e.capacity() >= 3);
}
