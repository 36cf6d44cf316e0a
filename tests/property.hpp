#pragma once
// rapidcheck inside Catch2 with a per-property CI budget. The number of cases is `ci_cases`
// (1 in the sanitizer build, test_paths.hpp sanitized()) unless FEBEMESH_PROPERTY_CASES or
// RC_PARAMS (max_success=N) says otherwise. A failure prints the seed and the shrunk
// counterexample; replay with RC_PARAMS="seed=S".

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <rapidcheck.h>

namespace febemesh::test {

/// Whether the case count was asked for (FEBEMESH_PROPERTY_CASES, or max_success in RC_PARAMS).
inline bool property_cases_given() {
  const char* params = std::getenv("RC_PARAMS");
  return std::getenv("FEBEMESH_PROPERTY_CASES") != nullptr ||
         (params != nullptr && std::string(params).find("max_success") != std::string::npos);
}

/// Runs `testable` as a rapidcheck property in a Catch2 section. In the CI budget (no case
/// count given) it tries `ci_cases` cases (1 under the sanitizers, where each is 5-10x slower).
template <typename Testable>
void prop(const std::string& description, int ci_cases, Testable&& testable) {
  SECTION(description) {
    rc::detail::TestParams params = rc::detail::configuration().testParams;
    if (!property_cases_given()) {
      params.maxSuccess = sanitized() ? std::min(ci_cases, 1) : ci_cases;
    }
    rc::detail::TestMetadata metadata;
    metadata.id = description;
    metadata.description = description;
    const auto result = rc::detail::checkTestable(std::forward<Testable>(testable), metadata, params);
    std::ostringstream ss;
    rc::detail::printResultMessage(result, ss);
    INFO(description << "\n" << ss.str());
    CHECK(result.template is<rc::detail::SuccessResult>());
  }
}

}  // namespace febemesh::test
