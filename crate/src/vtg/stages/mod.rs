//! The stages of the VTG paper, applied to one path: the B-spline (VTG eq. 21–22) and its
//! least-squares fit, the walk of Algorithm 1 (VTG eq. 27–28), and the feed limits of
//! VTG eq. 29–30.

pub(crate) mod bspline;
pub(crate) mod feed;
pub(crate) mod fit;
pub(crate) mod kinematics;
pub(crate) mod resample;
pub(crate) mod thin;
