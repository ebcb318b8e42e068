//! Infill regeneration and the energy-driven search over pattern, infill angle and orientation.
