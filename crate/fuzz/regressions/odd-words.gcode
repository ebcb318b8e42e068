G1 X1 X2
G1 X- Y1
G0 (unclosed X5
G1 X1.2.3
G1 Xnan Yinf
G28 X Y
G29.1 Z0.1
N-*99
N1e400 G1 X1
M117 Printing G1 X(y) 50% ✓
M486 S0 AObject_1
%
X10 Y5
g01x1y2z.3
