// A hub flange: a disk (r 1, 0.3 thick) with a hub (r 0.5, 0.8 high), a bore (r 0.3) and six
// bolt holes (r 0.09) on a 0.75 circle.
// A test part for febemesh mesh3d (examples/3d/README.md). The surface flange.stl is made by
//   gmsh flange.geo -2 -bin -format stl -o flange.stl        (Gmsh 4.8.4, OpenCASCADE kernel)
// Gmsh winds each face's triangles by that face's own parametrisation, so its STL may be closed
// but not consistently wound (block.stl: 36 edges run the same way by both triangles); febemesh
// orients such a surface.
SetFactory("OpenCASCADE");
Cylinder(1) = {0,0,0, 0,0,0.3, 1.0};
Cylinder(2) = {0,0,0, 0,0,0.8, 0.5};
Cylinder(3) = {0,0,-0.1, 0,0,1.0, 0.3};
For i In {0:5}
  Cylinder(10+i) = {0.75*Cos(i*Pi/3), 0.75*Sin(i*Pi/3), -0.1, 0,0,0.5, 0.09};
EndFor
u() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };
BooleanDifference{ Volume{u()}; Delete; }{ Volume{3,10:15}; Delete; }
Mesh.CharacteristicLengthMax = 0.08;
