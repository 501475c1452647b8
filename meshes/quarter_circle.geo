// Quarter circle of radius 1 in the x-y plane, from (0,0,0) leaving along +x, centre (0,1,0):
// the centre line of Schwab & Meijaard 2.2 and 2.4.
Point(1) = {0, 0, 0};
Point(2) = {0, 1, 0};
Point(3) = {1, 1, 0};
Circle(1) = {1, 2, 3};
