G0 X118.743 Y107.995
G0 F7200 X119.294 Y107.98
G1 F1500 X122.651 Y111.337 E3202.5969
G0 X122.721 Y111.407
G0 F7200 X122.651 Y110.771
G1 F1500 X119.86 Y107.98 E3202.72818
G0 X119.79 Y107.91
G0 F7200 X120.425 Y107.98
G1 F1500 X122.651 Y110.206 E3202.83288
G0 X122.721 Y110.276
G0 F7200 X122.65 Y109.639
G1 F1500 X120.991 Y107.98 E3202.91092
G0 X120.921 Y107.91
G0 F7200 X121.557 Y107.98
G1 F1500 X122.65 Y109.074 E3202.96235
G0 X122.72 Y109.144
G0 F7200 X122.65 Y108.508
G1 F1500 X122.122 Y107.98 E3202.98719
G1 F2700 E3196.48719
G0 F7200 X118.813 Y108.631
G1 F2700 E3202.98719
G1 F1500 X122 Y111.818 E3203.13709
G0 X122.07 Y111.888
G0 F7200 X121.434 Y111.818
G1 F1500 X118.813 Y109.197 E3203.26038
G0 X118.743 Y109.127
G0 F7200 X118.813 Y109.762
G1 F1500 X120.869 Y111.818 E3203.35709
G0 X120.939 Y111.888
G0 F7200 X120.303 Y111.818
G1 F1500 X118.813 Y110.328 E3203.42717
G0 X118.743 Y110.258
G0 F7200 X118.813 Y110.894
G1 F1500 X119.737 Y111.818 E3203.47063
G0 X119.807 Y111.888
G0 F7200 X119.172 Y111.818
G1 F1500 X118.813 Y111.459 E3203.48752
;TIME_ELAPSED:3485.137790
G1 F2700 E3196.98752
M107
M104 S0 ;extruder heater off
M140 S0 ;heated bed heater off (if you have it)
G91 ;relative positioning
G1 E-1 F300  ;retract the filament a bit before lifting the nozzle, to release some of the pressure
G1 Z+0.5 E-5 X-20 Y-20 F9000 ;move Z up a bit and retract filament even more
G28 X0 Y0 ;move X/Y to min endstops, so the head is out of the way
M84 ;steppers off
G90 ;absolute positioning
M104 S0
;End of Gcode
;SETTING_3 {"global_quality": "[general]\\nversion = 2\\nname = AnetA6Profiles\\
;SETTING_3 ndefinition = prusa_i3\\n\\n[metadata]\\nquality_type = normal\\ntype
;SETTING_3  = quality_changes\\n\\n[values]\\nspeed_wall_x = =speed_wall * 2\\ni
;SETTING_3 nfill_pattern = concentric\\nraft_interface_thickness = 0.2\\nadhesio
;SETTING_3 n_type = skirt\\nspeed_travel = =speed_print if magic_spiralize else 
;SETTING_3 120\\nraft_surface_line_spacing = 1.0\\nraft_base_line_width = 0.7\\n
;SETTING_3 raft_margin = 5\\nlayer_height_0 = 0.2\\nspeed_wall_0 = =speed_wall\\
;SETTING_3 nsupport_xy_distance = 1.2\\nskirt_line_count = 2\\nretraction_speed 
;SETTING_3 = 45\\nmaterial_print_temperature = 195\\nsupport_pattern = concentri
;SETTING_3 c\\nskirt_brim_minimal_length = 500\\nskirt_gap = 5\\nwall_thickness 
;SETTING_3 = 0.8\\ncool_fan_speed = 70.0\\nprime_tower_size = 8.660254037844387\
;SETTING_3 \ninfill_sparse_density = 15\\nbrim_line_count = 10\\nraft_interface_
;SETTING_3 line_spacing = 1.0\\ntop_thickness = 0.8\\ncool_min_layer_time = 3\\n
;SETTING_3 material_diameter = 1.75\\nraft_interface_line_width = 0.2\\nlayer_he
;SETTING_3 ight = 0.2\\nspeed_print = 50\\nraft_base_line_spacing = 1.0\\nsuppor
;SETTING_3 t_type = everywhere\\nsupport_infill_rate = 10\\nspeed_topbottom = =s
;SETTING_3 peed_print / 2\\ncool_min_speed = 19\\nmaterial_bed_temperature = 50\
;SETTING_3 \nretraction_combing = off\\nmaterial_flow = 100\\ncool_fan_speed_min
;SETTING_3  = =cool_fan_speed\\nbottom_thickness = 0.8\\ncool_fan_speed_max = =c
;SETTING_3 ool_fan_speed\\nspeed_infill = =speed_print\\nsupport_z_distance = 0.
;SETTING_3 45\\nsupport_enable = False\\n\\n"}
