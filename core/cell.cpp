// Placeholder translation unit so that febemesh_core links before the tree lands.
