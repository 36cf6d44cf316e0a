// The only test source compiled with the clone's absolute paths (see test_paths.hpp).

namespace febemesh::test {

const char* data_dir() { return FEBEMESH_TEST_DATA_DIR; }
const char* source_dir() { return FEBEMESH_TEST_SOURCE_DIR; }
const char* cli_path() { return FEBEMESH_TEST_CLI; }
#ifdef FEBEMESH_TEST_SANITIZED
bool sanitized() { return true; }
#else
bool sanitized() { return false; }
#endif

}  // namespace febemesh::test
