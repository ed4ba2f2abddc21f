// Block [0, 1] x [0, 1] x [0, 1] of two layers: bottom (z < 0.5) and top (z > 0.5).
// Physical groups (names become femkit tags):
//   surfaces: bottom_face (z = 0), top_face (z = 1), sides (the four vertical sides of both
//             layers), boundary (all of them)
//   volumes:  bottom, top
// Regenerate the .msh: see README.md in this folder.
SetFactory("OpenCASCADE");
h = 0.2;
Mesh.MeshSizeMax = h;

Box(1) = {0, 0, 0, 1, 1, 0.5};
Box(2) = {0, 0, 0.5, 1, 1, 0.5};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }

eps = 1e-6;
zlo() = Surface In BoundingBox{-eps, -eps, -eps, 1 + eps, 1 + eps, eps};
zhi() = Surface In BoundingBox{-eps, -eps, 1 - eps, 1 + eps, 1 + eps, 1 + eps};
mid() = Surface In BoundingBox{-eps, -eps, 0.5 - eps, 1 + eps, 1 + eps, 0.5 + eps};
all() = Surface{:};
side() = all();
side() -= zlo();
side() -= zhi();
side() -= mid();
outer() = zlo();
outer() += zhi();
outer() += side();

Physical Surface("bottom_face", 1) = zlo();
Physical Surface("top_face", 2) = zhi();
Physical Surface("sides", 3) = side();
Physical Surface("boundary", 4) = outer();
Physical Volume("bottom", 5) = {1};
Physical Volume("top", 6) = {2};
