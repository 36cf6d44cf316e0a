#pragma once
// What each fuzz target does with one input, shared by the libFuzzer targets (tests/fuzz) and
// the unit test that replays the inputs they found (tests/dim2/test_fuzz_regressions.cpp).
// InputError is the expected outcome of bad input and is swallowed here; any other exception
// escapes (the fuzz driver turns it into a crash), as do crashes and sanitizer reports.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "../scratch_dir.hpp"
#include "core/error.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/read_native.hpp"
#include "dim2/read_poly.hpp"
#include "dim2/read_svg.hpp"
#include "dim3/read_surface.hpp"

namespace febemesh::fuzz {

/// Accepted domains also go through CurveBoundary (the whole-input checks), as the CLI does.
inline void check_domain_input(const dim2::Domain& d) { (void)dim2::CurveBoundary(d); }

inline void svg_input(std::string_view data) {
  try {
    check_domain_input(dim2::parse_svg(std::string(data), "fuzz.svg"));
  } catch (const InputError&) {
  }
}

inline void native_input(std::string_view data) {
  try {
    check_domain_input(dim2::parse_native(std::string(data), "fuzz.json"));
  } catch (const InputError&) {
  }
}

/// The .poly text, then (after the first NUL byte, if any) the companion .node text.
inline void poly_input(std::string_view data) {
  const std::size_t nul = data.find('\0');
  const std::string poly(data.substr(0, nul));
  const std::string node = nul == std::string_view::npos ? std::string() : std::string(data.substr(nul + 1));
  try {
    check_domain_input(dim2::parse_poly(poly, "fuzz.poly", node, "fuzz.node"));
  } catch (const InputError&) {
  }
}

inline void off_input(std::string_view data) {
  std::istringstream in{std::string(data)};
  try {
    (void)dim3::read_off(in, "fuzz.off");
  } catch (const InputError&) {
  }
}

/// The bytes as an .stl file read through OpenMesh (read_with_openmesh, as read_surface does
/// for .stl), then indexed as a Surface. The file is in a scratch folder of its own (per process
/// and input), removed on the way out also when an exception other than InputError escapes.
inline void stl_input(std::string_view data) {
  const test::ScratchDir dir("fuzz");
  const std::filesystem::path path = dir.path() / "input.stl";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
  }
  try {
    (void)dim3::Surface(dim3::read_with_openmesh(path.string()));
  } catch (const InputError&) {
  }
}

/// The bytes as OBJ or PLY (read_obj, read_ply), then indexed as a Surface.
inline void obj_input(std::string_view data) {
  std::istringstream in{std::string(data)};
  try {
    (void)dim3::Surface(dim3::read_obj(in, "fuzz.obj"));
  } catch (const InputError&) {
  }
}

inline void ply_input(std::string_view data) {
  std::istringstream in{std::string(data), std::ios::in | std::ios::binary};
  try {
    (void)dim3::Surface(dim3::read_ply(in, "fuzz.ply"));
  } catch (const InputError&) {
  }
}

}  // namespace febemesh::fuzz
