// libFuzzer target: the STL reader (ASCII and binary, through OpenMesh; fuzz_inputs.hpp says
// what counts as a bug). OpenMesh reads files only, so each input goes through a temporary file.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  febemesh::fuzz::stl_input(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
