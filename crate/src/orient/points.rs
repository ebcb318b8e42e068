//! Point-and-vector toolpaths as robotic cells use them: one tool-tip position and one tool
//! vector per point, as CSV (`x,y,z,i,j,k`, optional header, a blank line or a different
//! `path` column value starts a new path) or JSON (an array of `{x, y, z, i, j, k, path?}`
//! objects).

use serde::{Deserialize, Serialize};

use crate::error::{Error, ErrorKind};

/// One point of a point-vector path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointVector {
    /// Tool-tip position, mm.
    pub x: f64,
    /// Tool-tip position, mm.
    pub y: f64,
    /// Tool-tip position, mm.
    pub z: f64,
    /// Tool vector (tip → nozzle), any length but not zero.
    pub i: f64,
    /// Tool vector.
    pub j: f64,
    /// Tool vector.
    pub k: f64,
    /// Path (layer) number: a change starts a new continuous path.
    #[serde(default)]
    pub path: u32,
}

/// Largest number of points accepted.
pub const MAX_POINTS: usize = 10_000_000;

fn invalid(line: u32, reason: &'static str) -> Error {
    Error::new(line, 0, ErrorKind::InvalidOption { reason })
}

/// Parses CSV point-vector data.
pub fn parse_csv(input: &[u8]) -> Result<Vec<PointVector>, Error> {
    let text = std::str::from_utf8(input).map_err(|_| invalid(0, "CSV is not UTF-8 text"))?;
    let mut out = Vec::new();
    let mut path = 0u32;
    let mut gap = false;
    for (n, raw) in text.lines().enumerate() {
        let number = u32::try_from(n + 1).unwrap_or(u32::MAX);
        let line = raw.trim();
        if line.is_empty() {
            gap = !out.is_empty();
            continue;
        }
        if line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split([',', ';', '\t']).map(str::trim).collect();
        let nums: Option<Vec<f64>> = fields.iter().map(|f| f.parse::<f64>().ok()).collect();
        let Some(nums) = nums else {
            if out.is_empty() && fields.first().is_some_and(|f| f.eq_ignore_ascii_case("x")) {
                continue; // header
            }
            return Err(invalid(number, "CSV row is not numbers x,y,z,i,j,k[,path]"));
        };
        if !(6..=7).contains(&nums.len()) {
            return Err(invalid(number, "CSV row needs 6 numbers x,y,z,i,j,k"));
        }
        let g = |k: usize| nums.get(k).copied().unwrap_or(0.0);
        let (x, y, z, i, j, k) = (g(0), g(1), g(2), g(3), g(4), g(5));
        let extra = nums.get(6);
        if gap {
            path = path.saturating_add(1);
            gap = false;
        }
        let p = match extra {
            Some(&v) if v.is_finite() && v >= 0.0 && v <= f64::from(u32::MAX) => v as u32,
            Some(_) => return Err(invalid(number, "CSV path column must be a whole number")),
            None => path,
        };
        out.push(PointVector {
            x,
            y,
            z,
            i,
            j,
            k,
            path: p,
        });
        if out.len() > MAX_POINTS {
            return Err(invalid(number, "too many points (more than 10 000 000)"));
        }
    }
    Ok(out)
}

/// Parses JSON point-vector data.
pub fn parse_json(input: &[u8]) -> Result<Vec<PointVector>, Error> {
    let points: Vec<PointVector> = serde_json::from_slice(input).map_err(|_| {
        invalid(
            0,
            "JSON must be an array of {x, y, z, i, j, k, path?} objects",
        )
    })?;
    if points.len() > MAX_POINTS {
        return Err(invalid(0, "too many points (more than 10 000 000)"));
    }
    Ok(points)
}

/// Writes CSV with a header; paths are separated by a blank line.
pub fn write_csv(points: &[PointVector]) -> Vec<u8> {
    let mut out = String::from("x,y,z,i,j,k\n");
    let mut last = points.first().map(|p| p.path);
    for p in points {
        if Some(p.path) != last {
            out.push('\n');
            last = Some(p.path);
        }
        // Shortest round-trip form: the vectors read back are bit for bit the ones written.
        out.push_str(&format!(
            "{},{},{},{},{},{}\n",
            p.x, p.y, p.z, p.i, p.j, p.k
        ));
    }
    out.into_bytes()
}

/// Writes JSON.
pub fn write_json(points: &[PointVector]) -> Vec<u8> {
    serde_json::to_vec(points).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_with_header_and_paths() {
        let pts = parse_csv(b"x,y,z,i,j,k\n0,0,0,0,0,1\n1,0,0,0,0,1\n\n2,0,0,0,0,1\n")
            .unwrap_or_default();
        assert_eq!(pts.len(), 3);
        assert_eq!((pts[0].path, pts[1].path, pts[2].path), (0, 0, 1));
        assert!(parse_csv(b"0,0,0,0,0\n").is_err());
    }

    #[test]
    fn json_round_trip() {
        let pts = parse_json(br#"[{"x":1,"y":2,"z":3,"i":0,"j":0,"k":1}]"#).unwrap_or_default();
        assert_eq!(pts.len(), 1);
        assert_eq!(parse_json(&write_json(&pts)).unwrap_or_default(), pts);
    }
}
