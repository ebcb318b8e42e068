//! Families of parallel lines clipped to a region by a scanline sweep: rectilinear, grid,
//! triangles, tri-hexagon.
//!
//! Lines of a family are `v = offset + k·S` in the frame turned by the family's angle, with
//! `k` counted from the bed origin, so consecutive layers put their lines in the same places
//! (as slicers do: grid and triangle walls stack). Each scanline is cut by the region's edges
//! under the even-odd rule; the inside spans become segments. The sweep keeps them in row
//! order, which the linker walks as a zigzag.

use super::super::geom::{cos_sin_deg, Region, P2};

/// Most scanlines of one family (hostile-input bound).
const MAX_ROWS: usize = 20_000;

/// Segments of the family at `angle_deg` with spacing `spacing` and offset `offset` (mm,
/// across the lines), clipped to `region`, grouped by row in sweep order.
pub(crate) fn family(
    region: &Region,
    angle_deg: f64,
    spacing: f64,
    offset: f64,
) -> Vec<Vec<[P2; 2]>> {
    let (c, s) = cos_sin_deg(angle_deg);
    // Turn the region by -angle: the lines become horizontal (v = y').
    let to_local = |p: P2| [c * p[0] + s * p[1], -s * p[0] + c * p[1]];
    let to_world = |q: P2| [c * q[0] - s * q[1], s * q[0] + c * q[1]];
    let edges: Vec<(P2, P2)> = region
        .iter()
        .flat_map(|contour| {
            let n = contour.len();
            (0..n).map(move |i| (contour[i], contour[(i + 1) % n]))
        })
        .map(|(a, b)| (to_local(a), to_local(b)))
        .collect();
    let (lo, hi) = edges
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
            (lo.min(a[1]).min(b[1]), hi.max(a[1]).max(b[1]))
        });
    if spacing.is_nan() || spacing <= 0.0 || !lo.is_finite() || !hi.is_finite() {
        return Vec::new();
    }
    let k0 = ((lo - offset) / spacing).ceil();
    let k1 = ((hi - offset) / spacing).floor();
    if k1.is_nan() || k0.is_nan() || k1 < k0 || (k1 - k0) as usize > MAX_ROWS {
        return Vec::new();
    }
    let mut rows = Vec::new();
    let mut xs: Vec<f64> = Vec::new();
    let mut k = k0;
    while k <= k1 {
        let y = offset + k * spacing;
        k += 1.0;
        xs.clear();
        for (a, b) in &edges {
            if (a[1] > y) != (b[1] > y) {
                xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
            }
        }
        xs.sort_by(f64::total_cmp);
        let row: Vec<[P2; 2]> = xs
            .chunks_exact(2)
            .filter(|p| p[1] - p[0] > 1e-3)
            .map(|p| [to_world([p[0], y]), to_world([p[1], y])])
            .collect();
        if !row.is_empty() {
            rows.push(row);
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_rows_at_0_and_45() {
        let sq: Region = vec![vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]];
        let rows = family(&sq, 0.0, 1.0, 0.5);
        assert_eq!(rows.len(), 10);
        let len: f64 = rows
            .iter()
            .flatten()
            .map(|s| super::super::super::geom::dist(s[0], s[1]))
            .sum();
        assert!((len - 100.0).abs() < 1e-9);
        let rows = family(&sq, 45.0, 1.0, 0.0);
        let len: f64 = rows
            .iter()
            .flatten()
            .map(|s| super::super::super::geom::dist(s[0], s[1]))
            .sum();
        // Area / spacing, up to the ends.
        assert!((len - 100.0).abs() < 3.0, "{len}");
    }
}
