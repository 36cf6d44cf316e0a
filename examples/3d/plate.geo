// A sheet-metal plate 2 x 2 x 0.05 with a bore (r 0.4): thinner than the octants of levels 4
// and 5 everywhere (0.38 and 0.76 of an octant), 1.5 level-6 octants thick.
// A test part for febemesh mesh3d (examples/3d/README.md). The surface plate.stl is made by
//   gmsh plate.geo -2 -bin -format stl -o plate.stl        (Gmsh 4.8.4, OpenCASCADE kernel)
// Gmsh winds each face's triangles by that face's own parametrisation, so its STL may be closed
// but not consistently wound (block.stl: 36 edges run the same way by both triangles); febemesh
// orients such a surface.
SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 2,2,0.05};
Cylinder(2) = {1,1,-0.1, 0,0,0.3, 0.4};
BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.CharacteristicLengthMax = 0.08;
