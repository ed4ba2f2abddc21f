// Rectangular plate [0, 2] x [0, 1] with a circular hole of radius 0.25 centred at (1, 0.5).
// Physical groups (names become femkit tags):
//   curves:  left, right, bottom, top, outer (all four sides), hole (the circle),
//            boundary (sides and hole)
//   surface: plate
// Regenerate the .msh: see README.md in this folder.
h = 0.05;
Mesh.MeshSizeMax = h;

Point(1) = {0, 0, 0, h};
Point(2) = {2, 0, 0, h};
Point(3) = {2, 1, 0, h};
Point(4) = {0, 1, 0, h};
Line(1) = {1, 2};  // bottom
Line(2) = {2, 3};  // right
Line(3) = {3, 4};  // top
Line(4) = {4, 1};  // left

// hole: centre point 5, four quarter arcs
Point(5) = {1, 0.5, 0, h};
Point(6) = {1.25, 0.5, 0, h};
Point(7) = {1, 0.75, 0, h};
Point(8) = {0.75, 0.5, 0, h};
Point(9) = {1, 0.25, 0, h};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

Physical Curve("left", 1) = {4};
Physical Curve("right", 2) = {2};
Physical Curve("bottom", 3) = {1};
Physical Curve("top", 4) = {3};
Physical Curve("outer", 5) = {1, 2, 3, 4};
Physical Curve("hole", 6) = {5, 6, 7, 8};
Physical Curve("boundary", 7) = {1, 2, 3, 4, 5, 6, 7, 8};
Physical Surface("plate", 8) = {1};
