//! The original infill's line spacing, measured from its lines.
//!
//! Area over length (`A / L`) counts the connectors a slicer prints along the boundary as
//! infill lines, which shrinks the spacing by the connectors' share (about 10 % for PrusaSlicer's
//! rectilinear at 45°). Where the original is made of straight line families (rectilinear,
//! grid, triangles, …) the spacing is measured directly: long moves (over three times the
//! `A / L` estimate) are grouped by direction; within a layer, the offsets of the lines of one
//! direction across that direction are sorted, and the gaps between neighbouring lines give the
//! pitch `P` (median over the file). With `F` families per layer (median), the spacing of the
//! equivalent rectilinear infill is `P / F`. Curved originals (gyroid, honeycomb) have no long
//! parallel lines and keep `A / L`.

use super::geom::P2;

/// A long infill move: layer, direction (degrees in [0, 180)), midpoint.
pub(crate) struct Line {
    pub layer: usize,
    pub dir_deg: f64,
    pub mid: P2,
}

/// The measured spacing, or `None` when the lines do not allow it.
pub(crate) fn measured(lines: &[Line], estimate: f64) -> Option<f64> {
    if lines.len() < 8 || !(estimate.is_finite() && estimate > 0.0) {
        return None;
    }
    let mut layers: Vec<usize> = lines.iter().map(|l| l.layer).collect();
    layers.sort_unstable();
    layers.dedup();
    let mut gaps: Vec<f64> = Vec::new();
    let mut families: Vec<usize> = Vec::new();
    for layer in layers {
        let here: Vec<&Line> = lines.iter().filter(|l| l.layer == layer).collect();
        // Directions, 1° bins.
        let mut dirs: Vec<(i64, usize)> = Vec::new();
        for l in &here {
            let b = (l.dir_deg.round() as i64).rem_euclid(180);
            match dirs.iter_mut().find(|d| d.0 == b) {
                Some(d) => d.1 += 1,
                None => dirs.push((b, 1)),
            }
        }
        let major: Vec<i64> = dirs
            .iter()
            .filter(|d| d.1 >= 3 && d.1 * 5 >= here.len())
            .map(|d| d.0)
            .collect();
        if major.is_empty() {
            continue;
        }
        families.push(major.len());
        for &b in &major {
            let a = (b as f64).to_radians();
            let n = [-crate::math::sin(a), crate::math::cos(a)];
            let mut offsets: Vec<f64> = here
                .iter()
                .filter(|l| ((l.dir_deg.round() as i64).rem_euclid(180)) == b)
                .map(|l| n[0] * l.mid[0] + n[1] * l.mid[1])
                .collect();
            offsets.sort_by(f64::total_cmp);
            gaps.extend(
                offsets
                    .windows(2)
                    .map(|w| w[1] - w[0])
                    .filter(|g| *g > 0.2 * estimate && *g < 20.0 * estimate),
            );
        }
    }
    if gaps.len() < 8 || families.is_empty() {
        return None;
    }
    gaps.sort_by(f64::total_cmp);
    families.sort_unstable();
    let pitch = gaps.get(gaps.len() / 2).copied()?;
    let f = families.get(families.len() / 2).copied()? as f64;
    let s = pitch / f;
    (s.is_finite() && s > 0.05).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_lines_two_apart() {
        let lines: Vec<Line> = (0..20)
            .map(|k| Line {
                layer: 0,
                dir_deg: 0.0,
                mid: [5.0, 2.0 * k as f64],
            })
            .collect();
        assert!((measured(&lines, 1.8).unwrap() - 2.0).abs() < 1e-12);
        // A grid: two families 4 apart are a rectilinear 2.
        let grid: Vec<Line> = (0..20)
            .flat_map(|k| {
                [
                    Line {
                        layer: 0,
                        dir_deg: 0.0,
                        mid: [5.0, 4.0 * k as f64],
                    },
                    Line {
                        layer: 0,
                        dir_deg: 90.0,
                        mid: [4.0 * k as f64, 5.0],
                    },
                ]
            })
            .collect();
        assert!((measured(&grid, 1.8).unwrap() - 2.0).abs() < 1e-12);
    }
}
