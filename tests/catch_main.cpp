// Test main: FEBEMESH_PROPERTY_CASES=N runs every rapidcheck property N times (default: each
// property's own CI budget). RC_PARAMS, when set, wins (e.g. RC_PARAMS="seed=123" to replay).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdlib>
#include <string>

int main(int argc, char* argv[]) {
  const char* cases = std::getenv("FEBEMESH_PROPERTY_CASES");
  if (cases != nullptr && std::getenv("RC_PARAMS") == nullptr) {
    const std::string params = "max_success=" + std::string(cases);
    setenv("RC_PARAMS", params.c_str(), 1);
  }
  return Catch::Session().run(argc, argv);
}
