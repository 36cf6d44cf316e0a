// An angle bracket: a 2 x 1 x 0.2 base and a 0.25-thick upright 1.4 high, a hole through each.
// A test part for febemesh mesh3d (examples/3d/README.md). The surface bracket.stl is made by
//   gmsh bracket.geo -2 -bin -format stl -o bracket.stl        (Gmsh 4.8.4, OpenCASCADE kernel)
// Gmsh winds each face's triangles by that face's own parametrisation, so its STL may be closed
// but not consistently wound (block.stl: 36 edges run the same way by both triangles); febemesh
// orients such a surface.
SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 2,1,0.2};
Box(2) = {0,0,0, 0.25,1,1.4};
Cylinder(3) = {1.3,0.5,-0.1, 0,0,0.4, 0.15};
Cylinder(4) = {-0.1,0.5,0.9, 0.5,0,0, 0.15};
u() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };
w() = BooleanDifference{ Volume{u()}; Delete; }{ Volume{3,4}; Delete; };
Mesh.CharacteristicLengthMax = 0.08;
