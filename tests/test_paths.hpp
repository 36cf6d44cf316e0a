#pragma once
// Where the tests find the shared data, the source tree and the built CLI.
//
// The paths are compiled into one small translation unit (test_paths.cpp) instead of every test
// source, so that a test object does not depend on where the project was cloned: a fresh clone
// (CI) then gets ccache hits for all the Catch2-heavy test sources. CMake force-includes this
// header into every test source, which keeps the macro names the tests have always used.

namespace febemesh::test {

const char* data_dir();    ///< the shared data (2d/*.svg, 3d/*.off)
const char* source_dir();  ///< the repository
const char* cli_path();    ///< the built `febemesh` executable
/// True in the sanitizer build (FEBEMESH_SANITIZE), where the suite runs a smaller budget:
/// one case per property unless more are asked for, fewer levels of the real data.
bool sanitized();

}  // namespace febemesh::test

#define FEBEMESH_DATA_DIR (::febemesh::test::data_dir())
#define FEBEMESH_SOURCE_DIR (::febemesh::test::source_dir())
#define FEBEMESH_CLI (::febemesh::test::cli_path())
