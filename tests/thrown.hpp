#pragma once
// The message of an exception a call throws, for the tests that check what a refusal says.

#include <string>

namespace febemesh::test {

/// The what() of the E that f() throws; empty when f returns. Any other exception goes on.
template <class E, class F>
std::string thrown_message(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return {};
}

}  // namespace febemesh::test
