// The disk of the rolling-disk scene (seed 001 §4.5.2; parameter_files/implicit/rolling_disk.prm):
// radius R = 0.1 m as a polar mesh of quadrangles (10 rings of 0.01 m, 64 sectors; triangles at
// the centre) so that its points lie on rings: the outermost ring of points (2 x 2 per element)
// is a circle, and the contact surface of the points (their extent V_p^(1/2)/2 around them) is
// round to 3e-5 m. A disk seeded on the grid's lattice ('shape = ball') has flat facets (the
// bottom row of 8 points is 4 cm wide) and rolls like a polygon (docs/implicit.md "Rolling disk").
// The centre is set so that the lowest point's extent touches the floor y = 0 (contact radius
// 0.0998266 m: outermost ring at 0.0974119 m plus r_p = 2.4414e-3 m).
R = 0.1; cx = 0.15; cy = 0.0998266; nr = 10; nt = 16;
Point(1) = {cx, cy, 0, 0.01};
Point(2) = {cx + R, cy, 0, 0.01};
Line(1) = {1, 2};
Transfinite Curve{1} = nr + 1;
a[] = Extrude {{0, 0, 1}, {cx, cy, 0}, Pi/2} { Curve{1}; Layers{nt}; Recombine; };
b[] = Extrude {{0, 0, 1}, {cx, cy, 0}, Pi/2} { Curve{a[0]}; Layers{nt}; Recombine; };
c[] = Extrude {{0, 0, 1}, {cx, cy, 0}, Pi/2} { Curve{b[0]}; Layers{nt}; Recombine; };
d[] = Extrude {{0, 0, 1}, {cx, cy, 0}, Pi/2} { Curve{c[0]}; Layers{nt}; Recombine; };
Coherence;
Physical Surface("disk") = {a[1], b[1], c[1], d[1]};
