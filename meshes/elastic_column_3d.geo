// The grid of parameter_files/verification/elastic_column_gravity_3d.prm made
// with gmsh: 0.0625 x 0.0625 x 1.25 m, 1 x 1 x 20 hexahedra, extruded in layers
// from the base square; the lower 16 cells (z < 1) form the volume "column",
// the upper 4 "head room". Boundary ids as the box grid (0 = x-, 1 = x+, 2 = y-,
// 3 = y+, 4 = z-, 5 = z+).
W  = 0.0625;
H  = 1.0;
Hg = 1.25;
Point(1) = {0, 0, 0};
Point(2) = {W, 0, 0};
Point(3) = {W, W, 0};
Point(4) = {0, W, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 2;
Transfinite Surface{1};
Recombine Surface{1};
// Extrude returns the top surface, the volume, then the side surfaces in the
// order of the boundary curves (1: y = 0, 2: x = W, 3: y = W, 4: x = 0)
col[]  = Extrude {0, 0, H} { Surface{1}; Layers{16}; Recombine; };
head[] = Extrude {0, 0, Hg - H} { Surface{col[0]}; Layers{4}; Recombine; };

Physical Surface("boundary 0 x-") = {col[5], head[5]};
Physical Surface("boundary 1 x+") = {col[3], head[3]};
Physical Surface("boundary 2 y-") = {col[2], head[2]};
Physical Surface("boundary 3 y+") = {col[4], head[4]};
Physical Surface("boundary 4 base") = {1};
Physical Surface("boundary 5 top") = {head[0]};
Physical Volume("column") = {col[1]};
Physical Volume("head room") = {head[1]};
