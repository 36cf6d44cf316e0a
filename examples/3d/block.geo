// A machined block 2 x 1.2 x 0.8: an open pocket, a vertical bore (r 0.2) meeting a
// horizontal cross bore (r 0.1, 0.1 above the floor: a thin floor) and a spherical dimple on top.
// A test part for febemesh mesh3d (examples/3d/README.md). The surface block.stl is made by
//   gmsh block.geo -2 -bin -format stl -o block.stl        (Gmsh 4.8.4, OpenCASCADE kernel)
// Gmsh winds each face's triangles by that face's own parametrisation, so its STL may be closed
// but not consistently wound (block.stl: 36 edges run the same way by both triangles); febemesh
// orients such a surface.
SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 2,1.2,0.8};
Box(2) = {0.3,0.3,0.4, 0.8,0.6,0.5};
Cylinder(3) = {1.6,0.6,-0.1, 0,0,1.0, 0.2};
Cylinder(4) = {-0.1,0.6,0.2, 2.2,0,0, 0.1};
Sphere(5) = {1.6,0.6,0.8, 0.3};
BooleanDifference{ Volume{1}; Delete; }{ Volume{2,3,4,5}; Delete; }
Mesh.CharacteristicLengthMax = 0.08;
