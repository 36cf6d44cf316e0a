// A pipe tee: a run (outer r 0.5, wall 0.12, 3 long) and a branch (outer r 0.4, wall 0.1).
// A test part for febemesh mesh3d (examples/3d/README.md). The surface tee.stl is made by
//   gmsh tee.geo -2 -bin -format stl -o tee.stl        (Gmsh 4.8.4, OpenCASCADE kernel)
// Gmsh winds each face's triangles by that face's own parametrisation, so its STL may be closed
// but not consistently wound (block.stl: 36 edges run the same way by both triangles); febemesh
// orients such a surface.
SetFactory("OpenCASCADE");
Cylinder(1) = {-1.5,0,0, 3,0,0, 0.5};
Cylinder(2) = {0,0,0, 0,0,1.2, 0.4};
Cylinder(3) = {-1.6,0,0, 3.2,0,0, 0.38};
Cylinder(4) = {0,0,0, 0,0,1.3, 0.3};
u() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };
BooleanDifference{ Volume{u()}; Delete; }{ Volume{3,4}; Delete; }
Mesh.CharacteristicLengthMax = 0.08;
