// The 24-member star dome (Meek & Tan 1984 and many later papers on corotational frames),
// units cm: the apex 1 at height 8.216; the inner nodes 2..7 on radius 25 at height 6.216,
// angles 0, 60, ..., 300 deg; the outer (supported) nodes 8..13 on radius 50 at height 0,
// angles 30, 90, ..., 330 deg. Members: 6 apex-inner ("ribs"), 6 inner ring ("ring"),
// 12 inner-outer ("legs", each inner node to its two nearest outer nodes).
// Read by demos/scenes/star_dome.toml (a copy of this file sits beside it).
h_apex = 8.216;
h_inner = 6.216;
r_inner = 25;
r_outer = 50;
Point(1) = {0, 0, h_apex};
Point(2) = {r_inner * Cos(0 * Pi / 3), r_inner * Sin(0 * Pi / 3), h_inner};
Point(3) = {r_inner * Cos(1 * Pi / 3), r_inner * Sin(1 * Pi / 3), h_inner};
Point(4) = {r_inner * Cos(2 * Pi / 3), r_inner * Sin(2 * Pi / 3), h_inner};
Point(5) = {r_inner * Cos(3 * Pi / 3), r_inner * Sin(3 * Pi / 3), h_inner};
Point(6) = {r_inner * Cos(4 * Pi / 3), r_inner * Sin(4 * Pi / 3), h_inner};
Point(7) = {r_inner * Cos(5 * Pi / 3), r_inner * Sin(5 * Pi / 3), h_inner};
Point(8) = {r_outer * Cos(Pi / 6 + 0 * Pi / 3), r_outer * Sin(Pi / 6 + 0 * Pi / 3), 0};
Point(9) = {r_outer * Cos(Pi / 6 + 1 * Pi / 3), r_outer * Sin(Pi / 6 + 1 * Pi / 3), 0};
Point(10) = {r_outer * Cos(Pi / 6 + 2 * Pi / 3), r_outer * Sin(Pi / 6 + 2 * Pi / 3), 0};
Point(11) = {r_outer * Cos(Pi / 6 + 3 * Pi / 3), r_outer * Sin(Pi / 6 + 3 * Pi / 3), 0};
Point(12) = {r_outer * Cos(Pi / 6 + 4 * Pi / 3), r_outer * Sin(Pi / 6 + 4 * Pi / 3), 0};
Point(13) = {r_outer * Cos(Pi / 6 + 5 * Pi / 3), r_outer * Sin(Pi / 6 + 5 * Pi / 3), 0};
// ribs: apex to each inner node
Line(1) = {1, 2};
Line(2) = {1, 3};
Line(3) = {1, 4};
Line(4) = {1, 5};
Line(5) = {1, 6};
Line(6) = {1, 7};
// ring: inner node to the next
Line(7) = {2, 3};
Line(8) = {3, 4};
Line(9) = {4, 5};
Line(10) = {5, 6};
Line(11) = {6, 7};
Line(12) = {7, 2};
// legs: inner node at angle 60 k to the outer nodes at 60 k - 30 and 60 k + 30
Line(13) = {2, 13};
Line(14) = {2, 8};
Line(15) = {3, 8};
Line(16) = {3, 9};
Line(17) = {4, 9};
Line(18) = {4, 10};
Line(19) = {5, 10};
Line(20) = {5, 11};
Line(21) = {6, 11};
Line(22) = {6, 12};
Line(23) = {7, 12};
Line(24) = {7, 13};
Physical Line("ribs") = {1, 2, 3, 4, 5, 6};
Physical Line("ring") = {7, 8, 9, 10, 11, 12};
Physical Line("legs") = {13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24};
Physical Point("apex") = {1};
Physical Point("base") = {8, 9, 10, 11, 12, 13};
