//! Families of parallel lines clipped to a region by a scanline sweep: rectilinear, grid,
//! triangles, tri-hexagon.
//!
//! Lines of a family are `v = offset + k·S` in the frame turned by the family's angle, with
//! `k` counted from the bed origin, so consecutive layers put their lines in the same places
//! (as slicers do: grid and triangle walls stack). Each scanline is cut by the region's edges
//! under the even-odd rule; the inside spans become segments. The sweep keeps them in row
//! order, which the linker walks as a zigzag.

use super::super::geom::{cos_sin_deg, dist, Path, Region, P2};

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

/// Where a scanline crosses the region's boundary: row, position along the row (local frame),
/// contour, edge and parameter along the edge.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    row: usize,
    x: f64,
    contour: usize,
    edge: usize,
    t: f64,
}

/// A family clipped to a region, as segments with the crossings at their ends.
struct Clipped {
    crossings: Vec<Crossing>,
    /// Segments: the crossing ids of their two ends (left, right in the local frame).
    segs: Vec<[usize; 2]>,
    /// For every crossing, the end of a segment it is (`seg * 2 + side`), if any.
    end_of: Vec<Option<usize>>,
    to_world: (f64, f64),
    spacing: f64,
    offset: f64,
    k0: f64,
}

impl Clipped {
    fn point(&self, c: usize) -> P2 {
        let cr = self.crossings[c];
        let y = self.offset + (self.k0 + cr.row as f64) * self.spacing;
        let (co, si) = self.to_world;
        [co * cr.x - si * y, si * cr.x + co * y]
    }
}

/// Clips the family at `angle_deg` to `region`, keeping for every segment end the boundary
/// edge it lies on (what [`chains`] links along).
fn clip(region: &Region, angle_deg: f64, spacing: f64, offset: f64) -> Option<Clipped> {
    let (c, s) = cos_sin_deg(angle_deg);
    let to_local = |p: P2| [c * p[0] + s * p[1], -s * p[0] + c * p[1]];
    let mut edges: Vec<(P2, P2, usize, usize)> = Vec::new();
    for (ci, contour) in region.iter().enumerate() {
        let n = contour.len();
        for i in 0..n {
            let (a, b) = (to_local(contour[i]), to_local(contour[(i + 1) % n]));
            if a[1] != b[1] {
                edges.push((a, b, ci, i));
            }
        }
    }
    let (lo, hi) = edges
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), e| {
            (lo.min(e.0[1]).min(e.1[1]), hi.max(e.0[1]).max(e.1[1]))
        });
    if spacing.is_nan() || spacing <= 0.0 || !lo.is_finite() || !hi.is_finite() {
        return None;
    }
    let k0 = ((lo - offset) / spacing).ceil();
    let k1 = ((hi - offset) / spacing).floor();
    if k1.is_nan() || k0.is_nan() || k1 < k0 || (k1 - k0) as usize > MAX_ROWS {
        return None;
    }
    // Edges by their lowest row, so each row looks only at the edges it can cross.
    let rows = (k1 - k0) as usize + 1;
    let mut active: Vec<Vec<usize>> = vec![Vec::new(); rows];
    for (i, (a, b, ..)) in edges.iter().enumerate() {
        let ylo = a[1].min(b[1]);
        let r = (((ylo - offset) / spacing).ceil() - k0).max(0.0) as usize;
        if let Some(v) = active.get_mut(r) {
            v.push(i);
        }
    }
    let mut out = Clipped {
        crossings: Vec::new(),
        segs: Vec::new(),
        end_of: Vec::new(),
        to_world: (c, s),
        spacing,
        offset,
        k0,
    };
    let mut live: Vec<usize> = Vec::new();
    let mut row_x: Vec<(f64, usize)> = Vec::new();
    for (r, starting) in active.iter().enumerate() {
        let y = offset + (k0 + r as f64) * spacing;
        live.extend(starting);
        live.retain(|&i| edges[i].0[1].max(edges[i].1[1]) >= y);
        row_x.clear();
        for &i in &live {
            let (a, b, ci, ei) = edges[i];
            if (a[1] > y) != (b[1] > y) {
                let t = (y - a[1]) / (b[1] - a[1]);
                let x = a[0] + t * (b[0] - a[0]);
                row_x.push((x, out.crossings.len()));
                out.crossings.push(Crossing {
                    row: r,
                    x,
                    contour: ci,
                    edge: ei,
                    t,
                });
            }
        }
        row_x.sort_by(|p, q| p.0.total_cmp(&q.0));
        out.end_of.resize(out.crossings.len(), None);
        for p in row_x.chunks_exact(2) {
            if p[1].0 - p[0].0 > 1e-3 {
                let k = out.segs.len();
                out.end_of[p[0].1] = Some(2 * k);
                out.end_of[p[1].1] = Some(2 * k + 1);
                out.segs.push([p[0].1, p[1].1]);
            }
        }
    }
    Some(out)
}

/// A link between two segment ends along the boundary: the other end and the path (from this
/// end's point to the other's, both included).
type Links = Vec<Vec<(usize, Path)>>;

/// The boundary links: two segment ends that follow each other along a contour, on the same
/// or neighbouring rows, joined by the contour between them when it is at most `max_len` long
/// (the contour between two consecutive crossings crosses no other line of the family).
fn links(cl: &Clipped, region: &Region, max_len: f64) -> Links {
    let mut links: Links = vec![Vec::new(); 2 * cl.segs.len()];
    let mut on: Vec<Vec<usize>> = vec![Vec::new(); region.len()];
    for (i, c) in cl.crossings.iter().enumerate() {
        on[c.contour].push(i);
    }
    for (ci, list) in on.iter_mut().enumerate() {
        let contour = &region[ci];
        let n = contour.len();
        list.sort_by(|&a, &b| {
            let (p, q) = (cl.crossings[a], cl.crossings[b]);
            p.edge.cmp(&q.edge).then(p.t.total_cmp(&q.t))
        });
        for k in 0..list.len() {
            let (a, b) = (list[k], list[(k + 1) % list.len()]);
            let (Some(ea), Some(eb)) = (cl.end_of[a], cl.end_of[b]) else {
                continue;
            };
            let (ra, rb) = (cl.crossings[a].row, cl.crossings[b].row);
            if a == b || ea / 2 == eb / 2 || ra.abs_diff(rb) > 1 {
                continue;
            }
            let mut path = vec![cl.point(a)];
            let mut len = 0.0;
            let (mut e, last) = (cl.crossings[a].edge, cl.crossings[b].edge);
            let wraps = (last, cl.crossings[b].t) <= (e, cl.crossings[a].t);
            let mut steps = 0;
            while (e != last || (wraps && steps == 0)) && len <= max_len && steps <= n {
                e = (e + 1) % n;
                let v = contour[e];
                len += dist(*path.last().unwrap_or(&v), v);
                path.push(v);
                steps += 1;
            }
            let pb = cl.point(b);
            len += dist(*path.last().unwrap_or(&pb), pb);
            path.push(pb);
            if len <= max_len && steps <= n {
                let back: Path = path.iter().rev().copied().collect();
                links[ea].push((eb, path));
                links[eb].push((ea, back));
            }
        }
    }
    links
}

/// Continues a chain from segment end `end` (already printed), taking boundary links to
/// unused segments, rows in direction `dir` first; returns the points after `end`'s own.
fn walk(cl: &Clipped, links: &Links, used: &mut [bool], end: usize, dir: i64) -> Path {
    let mut out = Path::new();
    let mut end = end;
    let mut dir = dir;
    loop {
        let row = |e: usize| cl.crossings[cl.segs[e / 2][e % 2]].row as i64;
        let here = row(end);
        let next = links[end]
            .iter()
            .filter(|(e, _)| !used[e / 2])
            .min_by_key(|(e, _)| match row(*e) - here {
                d if d == dir => 0,
                0 => 1,
                _ => 2,
            });
        let Some((e, path)) = next else { break };
        let step = row(*e) - here;
        if step != 0 {
            dir = step;
        }
        used[e / 2] = true;
        out.extend(path.iter().skip(1));
        let other = e ^ 1;
        out.push(cl.point(cl.segs[other / 2][other % 2]));
        end = other;
    }
    out
}

/// The family at `angle_deg` clipped to `region` and linked into zigzag chains: neighbouring
/// lines are joined along the region's boundary (as slicers' connected infill does) wherever
/// the boundary between their ends is at most `max_link` long and crosses no other line; each
/// chain is one continuous extrusion.
pub(crate) fn chains(
    region: &Region,
    angle_deg: f64,
    spacing: f64,
    offset: f64,
    max_link: f64,
) -> Vec<Path> {
    let Some(cl) = clip(region, angle_deg, spacing, offset) else {
        return Vec::new();
    };
    let links = links(&cl, region, max_link);
    let mut used = vec![false; cl.segs.len()];
    let mut out = Vec::new();
    for s in 0..cl.segs.len() {
        if used[s] {
            continue;
        }
        used[s] = true;
        let forward = walk(&cl, &links, &mut used, 2 * s + 1, 1);
        let backward = walk(&cl, &links, &mut used, 2 * s, -1);
        let mut chain: Path = backward.into_iter().rev().collect();
        chain.push(cl.point(cl.segs[s][0]));
        chain.push(cl.point(cl.segs[s][1]));
        chain.extend(forward);
        out.push(chain);
    }
    out
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

    #[test]
    fn chains_zigzag_and_go_round_holes() {
        use super::super::super::geom::{inside_tol, path_len};
        let sq: Region = vec![vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]];
        // A square: one zigzag, lines of 10 and connectors of 1 along the sides.
        let c = chains(&sq, 0.0, 1.0, 0.5, 3.0);
        assert_eq!(c.len(), 1);
        assert!(
            (path_len(&c[0]) - 109.0).abs() < 1e-9,
            "{}",
            path_len(&c[0])
        );
        // At 45°, still one chain.
        assert_eq!(chains(&sq, 45.0, 1.0, 0.5, 3.0).len(), 1);
        // A square hole in the middle: the rows it cuts split into two zigzags at most
        // (one each side, each continuing above), never one chain per cut row.
        let holed: Region = vec![
            sq[0].clone(),
            vec![[3.0, 3.0], [3.0, 7.0], [7.0, 7.0], [7.0, 3.0]],
        ];
        let c = chains(&holed, 0.0, 1.0, 0.5, 3.0);
        assert!(c.len() <= 3, "{}", c.len());
        for p in c.iter().flatten() {
            assert!(inside_tol(&holed, *p, 1e-9));
        }
        for w in c.iter().flat_map(|p| p.windows(2)) {
            let mid = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])];
            assert!(inside_tol(&holed, mid, 1e-9), "{mid:?}");
        }
        let all: f64 = c.iter().map(|p| path_len(p)).sum();
        // 10 rows (4 of them cut to 6 mm) and connectors.
        assert!(all > 84.0 && all < 110.0, "{all}");
    }
}
