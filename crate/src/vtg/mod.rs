//! Vibration-suppressed toolpath generation (VTG paper section 3, eq. 18–31, Algorithm 1).
