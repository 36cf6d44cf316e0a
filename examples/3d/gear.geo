// A spur-gear blank: a disk (r 1, 0.4 thick) with twelve 0.2 x 0.18 teeth and a bore (r 0.25).
// A test part for febemesh mesh3d (examples/3d/README.md). The surface gear.stl is made by
//   gmsh gear.geo -2 -bin -format stl -o gear.stl        (Gmsh 4.8.4, OpenCASCADE kernel)
// Gmsh winds each face's triangles by that face's own parametrisation, so its STL may be closed
// but not consistently wound (block.stl: 36 edges run the same way by both triangles); febemesh
// orients such a surface.
SetFactory("OpenCASCADE");
Cylinder(1) = {0,0,0, 0,0,0.4, 1.0};
For i In {0:11}
  Box(10+i) = {0.95,-0.09,0, 0.2,0.18,0.4};
  Rotate {{0,0,1},{0,0,0}, i*Pi/6} { Volume{10+i}; }
EndFor
Cylinder(30) = {0,0,-0.1, 0,0,0.6, 0.25};
u() = BooleanUnion{ Volume{1}; Delete; }{ Volume{10:21}; Delete; };
BooleanDifference{ Volume{u()}; Delete; }{ Volume{30}; Delete; }
Mesh.CharacteristicLengthMax = 0.06;
