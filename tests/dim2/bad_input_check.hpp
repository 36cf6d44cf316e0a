#pragma once
// Shared by the reader tests: a bad input must be refused with InputError whose message names the
// file, says where (line:column, coordinates or JSON pointer) and contains the expected reason.

#include <catch2/catch.hpp>
#include <regex>
#include <string>

#include "core/error.hpp"
#include "dim2/read_domain.hpp"

namespace febemesh::test {

struct BadInput {
  const char* file;   ///< in tests/dim2/bad_inputs
  const char* place;  ///< regex the message must contain, e.g. ":2:19: " or "near \\("
  const char* why;    ///< substring of the reason
};

inline std::string bad_input_path(const char* file) {
  return std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim2/bad_inputs/" + file;
}

inline void check_bad_input(const BadInput& c) {
  const std::string path = bad_input_path(c.file);
  INFO(path);
  std::string msg;
  try {
    (void)dim2::read_domain(path);
  } catch (const InputError& e) {
    msg = e.what();
  }
  INFO("message: " << msg);
  REQUIRE(!msg.empty());
  CHECK(msg.rfind(path, 0) == 0);  // starts with the file name
  CHECK(std::regex_search(msg, std::regex(c.place)));
  CHECK(msg.find(c.why) != std::string::npos);
}

}  // namespace febemesh::test
