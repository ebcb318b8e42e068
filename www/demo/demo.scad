// quietpath playground demo model: a small rounded tray (30 x 30 x 10 mm)
// with a 2 mm floor, 1.6 mm walls and an 8 mm hole through the floor.
// Sliced with PrusaSlicer into demo.gcode; see README.md in this folder.

$fn = 64;

size   = 30;   // outer width and depth, mm
height = 10;   // outer height, mm
radius = 4;    // corner radius, mm
wall   = 1.6;  // wall thickness, mm
floor_ = 2;    // floor thickness, mm
hole_d = 8;    // hole through the floor, mm

module rounded_square(s, r) {
    offset(r = r) square(s - 2 * r, center = true);
}

difference() {
    linear_extrude(height) rounded_square(size, radius);
    translate([0, 0, floor_])
        linear_extrude(height) rounded_square(size - 2 * wall, radius - wall);
    translate([0, 0, -1])
        cylinder(d = hole_d, h = floor_ + 2);
}
