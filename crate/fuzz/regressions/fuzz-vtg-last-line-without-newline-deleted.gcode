G21
; Absolute position mode
G90
; Relative Extruder mode
M83
; Start heating the Bed
M140 S43
; Home the axes
G28
; Wait till the Bed is heated
M190 S43
; Heated chamber G-code is not universal
;M141 S0
;M191 S0
;
; *** Main G-code ***
;
; BEGIN_LAYER_OBJECT z=0.263 z_thickness=0.263
;
; *** Selecting and Warming Extruder 1 to 195 C ***
; Head to the start of the next path
G1 X68.400 Y75.674 F6000
G4 P0
; Select the Tool (extruder)
T0
; Correct position for multi-nozzle
G1 X68.400 Y75.674 F6000
G4 P0
; Set temp and then wait
M104 S195
M109 S195
; PURGE OR PRIME HERE IF DESIRED
;
;
; Fan set to Cool value 50%
;
; 'Prime Pillar Path', 0.6 [feed mm/s], 9.5 [head mm/s]
G1 X68.4 Y75.674 Z0.313 E0 F9000
G1 X68.4 Y75.674 Z0.263 E0 F300
; 'Destring Prime'
G1 E1 F1875
; head speed 9.501953, filament speed 0.623381, preload 0.000000
G1 X68.297 Y75.699 E0.00694 F570.1
G1 X67.989 Y75.775 E0.02083
G1 X67.475 Y75.9 E0.03472
G1 X66.552 Y75.89 E0.06053
G1 X65.32 Y75.877 E0.08083
G1 X63.779 Y75.861 E0.10114
G1 X62.344 Y74.462 E0.13149
G1 X62.1 Y73.475 E0.0667
G1 X62.139 Y69.779 E0.24249
G1 X63.538 Y68.344 E0.13149
G1 X64.525 Y68.1 E0.0667
G1 X68.221 Y68.139 E0.2425
G1 X69.656 Y69.538 E0.13148
G1 X69.9 Y70.525 E0.06671
G1 X69.884 Y71.95 E0.09349
G1 X69.87 Y73.173 E0.08021
G1 X69.858 Y74.193 E0.06