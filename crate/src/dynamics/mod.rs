//! Machine dynamics: the lumped-mass model of an axis drive (VTG paper eq. 1–15), its response
//! to the planned trajectory, trajectory deviation and acceleration spectra.
