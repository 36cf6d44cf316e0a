// libFuzzer target: the PLY reader, ASCII and binary (read_ply); fuzz_inputs.hpp says what counts as a bug.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  febemesh::fuzz::ply_input(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
