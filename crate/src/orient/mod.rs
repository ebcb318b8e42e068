//! Tool-orientation smoothing for multi-axis toolpaths (orientation-smoothing paper, eq. 1–7).
