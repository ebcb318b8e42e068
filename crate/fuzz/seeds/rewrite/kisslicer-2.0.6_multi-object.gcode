; head speed 11.250001, filament speed 0.492043, preload 0.000000
G1 X65.33 Y70.679 E0.00516 F675
G1 X65.084 Y70.933 E0.01546
G1 X64.673 Y71.356 E0.02578
; Prepare for Destring
G1 X64.511 Y72.061 E0.03165
G1 X64.527 Y72.045 E0.00098
G1 X65.22 Y71.353 E0.04283
G1 X66.062 Y70.511 E0.05207
G1 X66.532 Y70.606 E0.02097
G1 X66.525 Y70.613 E0.00044
G1 X65.622 Y71.516 E0.05584
G1 X64.606 Y72.532 E0.06285
G1 X64.807 Y72.897 E0.01822
G1 X66.897 Y70.807 E0.12929
G1 X67.182 Y71.088 E0.0175
G1 X65.088 Y73.182 E0.12953
G1 X65.448 Y73.387 E0.01814
G1 X66.474 Y72.361 E0.06345
G1 X67.387 Y71.448 E0.05645
G1 X67.389 Y71.458 E0.00042
G1 X67.487 Y71.914 E0.02042
G1 X66.624 Y72.777 E0.05334
G1 X65.914 Y73.487 E0.04395
G1 X65.939 Y73.482 E0.00113
G1 X66.63 Y73.337 E0.03087
G1 X67.079 Y72.888 E0.02777
G1 X67.348 Y72.618 E0.01667
G1 X67.438 Y72.528 E0.00556
;
; 'Destring/Wipe/Jump Path', 0.0 [feed mm/s], 45.0 [head mm/s]
; 'Destring Suck'
G1 E-1 F1875
; head speed 45.000000, filament speed 0.000000, preload 0.000000
; Prepare for End-Of-Layer
G1 X67.438 Y72.528 Z5.05 E0 F300
;
; 'Travel/Ironing Path', 0.0 [feed mm/s], 150.0 [head mm/s]
G1 X67.414 Y72.283 E0 F9000
; head speed 150.000000, filament speed 0.000000, preload 0.000000
G1 X66.566 Y73.131 E0
G1 X66.283 Y73.98 E0
G1 X66.283 Y73.98 E0
; time estimate: pre = 43.943439, post = 42.301517
; Dwell time remaining = -32.301517
;
; Post-layer lift
G1 X66.283 Y73.98 Z5.314 E0 F300
; END_LAYER_OBJECT z=5.000
;
; *** Cooling Extruder 1 to 0 C and Retiring ***
; Same extruder, about to deselect, maybe retract before cooling down
; RETRACT HERE IF YOU WANT
G4 P0
M104 S0
;
; fan off
M107
; *** G-code Postfix ***
;
; All extruders are retired
; Move the head up / bed down
G91
G1 Z+10
G90
; turn off the bed & chamber (machine specific)
M140 S0
;M141 S0
; FILL THIS IN AS NEEDED
;
;
;
; Calculated-during-export Build Time: 10.16 minutes
; Estimated-in-GUI Build Time:         10.18 minutes
; Estimated-in-GUI Build Cost:         $0.03
;
; Filament used per extruder:
;    Ext #1  =   305.09 mm  (0.734 cm^3)
;
; *** Extrusion Time Breakdown ***
; * estimated time in [s]
; * before possibly slowing down for 'cool'
; * not including Z-travel
;
;	| Ext #1  | Path Type
;	========================================
;	| 18.2548 | Jump Path                  |
;	| 0       | Pillar Path                |
;	> 0       > Raft Path                  >
;	| 0       | Support Interface Path     |
;	| 0       | Support (may Stack) Path   |
;	| 160.073 | Perimeter Path             |
;	> 115.728 > Loop Path                  >
;	| 78.3098 | Solid Path                 |
;	| 20.747  | Sparse Infill Path         |
;	| 7.02163 | Stacked Sparse Infill Path |
;	> 7.42718 > Destring/Wipe/Jump Path    >
;	| 0       | Crown Path                 |
;	| 5.83886 | Prime Pillar Path          |
;	| 0       | Purge Path                 |
;	> 8.92957 > Travel/Ironing Path        >
;	| 0       | Pause Point                |
;	| 57.0375 | Extruder Warm-Up           |
;	========================================
; Total estimated (pre-cool) minutes: 7.99
