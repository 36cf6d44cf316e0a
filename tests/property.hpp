#pragma once
// rapidcheck inside Catch2 with a per-property CI budget. The number of cases is
// `ci_cases` unless FEBEMESH_PROPERTY_CASES or RC_PARAMS (max_success=N) says otherwise.
// A failure prints the seed and the shrunk counterexample; replay with RC_PARAMS="seed=S".

#include <cstdlib>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>
#include <rapidcheck.h>

namespace febemesh::test {

template <typename Testable>
void prop(const std::string& description, int ci_cases, Testable&& testable) {
  SECTION(description) {
    rc::detail::TestParams params = rc::detail::configuration().testParams;
    const bool overridden = std::getenv("FEBEMESH_PROPERTY_CASES") != nullptr ||
                            (std::getenv("RC_PARAMS") != nullptr &&
                             std::string(std::getenv("RC_PARAMS")).find("max_success") != std::string::npos);
    if (!overridden) params.maxSuccess = ci_cases;
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
