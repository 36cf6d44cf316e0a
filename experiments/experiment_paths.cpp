// The only experiment source compiled with the clone's absolute paths (see experiment_paths.hpp).
// Not an experiment itself: experiments/CMakeLists.txt links it into each of them.

namespace febemesh::experiments {

const char* data_dir() { return FEBEMESH_EXPERIMENT_DATA_DIR; }
const char* source_dir() { return FEBEMESH_EXPERIMENT_SOURCE_DIR; }

}  // namespace febemesh::experiments
