// Test main: FEBEMESH_PROPERTY_CASES=N runs every rapidcheck property N times (default: each
// property's own CI budget), also next to RC_PARAMS="seed=S"; a max_success in RC_PARAMS wins.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdlib>
#include <string>

int main(int argc, char* argv[]) {
  const char* cases = std::getenv("FEBEMESH_PROPERTY_CASES");
  if (cases != nullptr) {
    const char* given = std::getenv("RC_PARAMS");
    std::string params = given != nullptr ? given : "";
    if (params.find("max_success") == std::string::npos) {
      params += (params.empty() ? "" : " ") + std::string("max_success=") + cases;
      setenv("RC_PARAMS", params.c_str(), 1);
    }
  }
  return Catch::Session().run(argc, argv);
}
