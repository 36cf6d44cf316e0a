#pragma once
// Where the experiments find the shared data and the source tree (results/ goes there).
//
// The paths are compiled into one small translation unit (experiment_paths.cpp) instead of every
// experiment, so that an experiment's object does not depend on where the project was cloned and
// a fresh clone (CI) gets ccache hits. CMake force-includes this header into every experiment.

namespace febemesh::experiments {

const char* data_dir();    ///< the shared data (2d/*.svg, 3d/*.off)
const char* source_dir();  ///< the repository

}  // namespace febemesh::experiments

#define FEBEMESH_DATA_DIR (::febemesh::experiments::data_dir())
#define FEBEMESH_SOURCE_DIR (::febemesh::experiments::source_dir())
