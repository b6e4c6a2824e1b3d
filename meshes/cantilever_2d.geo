// 2D cantilever under self-weight (seed 001 §4.5.1: l = 8 m, b = h = 1 m, plane
// strain) and the background grid around it: [0, 9] x [-1, 2] m in six
// transfinite blocks of square cells of size h (axis-aligned, for MPM). The
// block [0, 8] x [0, 1] is the surface "beam" (material 0); the wall x = 0 is
// "boundary 1 wall" (clamp), the other outer sides "boundary 2 outer".
// For FEM on the beam alone, take the cells of "beam" (talus-mesh body source =
// grid, groups = beam, positions = gauss).
h = 0.25;
xs[] = {0, 8, 9};
ys[] = {-1, 0, 1, 2};
// points p(i, j) = 1 + i + 3 j
For j In {0:3}
  For i In {0:2}
    Point(1 + i + 3 * j) = {xs[i], ys[j], 0};
  EndFor
EndFor
// horizontal lines h(i, j): p(i,j) -> p(i+1,j), tag 100 + i + 2 j
For j In {0:3}
  For i In {0:1}
    Line(100 + i + 2 * j) = {1 + i + 3 * j, 2 + i + 3 * j};
    Transfinite Curve{100 + i + 2 * j} = Round((xs[i + 1] - xs[i]) / h) + 1;
  EndFor
EndFor
// vertical lines v(i, j): p(i,j) -> p(i,j+1), tag 200 + i + 3 j
For j In {0:2}
  For i In {0:2}
    Line(200 + i + 3 * j) = {1 + i + 3 * j, 4 + i + 3 * j};
    Transfinite Curve{200 + i + 3 * j} = Round((ys[j + 1] - ys[j]) / h) + 1;
  EndFor
EndFor
// blocks b(i, j), tag 1 + i + 2 j
For j In {0:2}
  For i In {0:1}
    Curve Loop(1 + i + 2 * j) = {100 + i + 2 * j, 201 + i + 3 * j, -(100 + i + 2 * (j + 1)), -(200 + i + 3 * j)};
    Plane Surface(1 + i + 2 * j) = {1 + i + 2 * j};
    Transfinite Surface{1 + i + 2 * j};
    Recombine Surface{1 + i + 2 * j};
  EndFor
EndFor

Physical Curve("boundary 1 wall") = {200, 203, 206};
Physical Curve("boundary 2 outer") = {100, 101, 106, 107, 202, 205, 208};
Physical Surface("beam") = {3};
Physical Surface("material 0") = {1, 2, 3, 4, 5, 6};
