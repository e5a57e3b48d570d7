//! A cloud field as a file: the condensed parcels the renderer draws
//! ([`CloudParcel`]), one per CSV row. `cumulus render --save-parcels`
//! writes the simulated field; `render`/`export --parcels` draw a field from
//! such a file instead of simulating (a saved frame, or a field written by
//! hand or by another tool, such as the towers the lighting is checked on).
//!
//! ```text
//! # comment lines start with '#'
//! id,x_m,y_m,z_m,radius_m,fill,cond_plane_z_m
//! 0,0,0,1500,500,1,1100
//! ```
//!
//! x, y horizontal and z up, in metres, z = 0 at the ground. Values are
//! written in the shortest form that reads back to the same `f32`, so a
//! saved field renders bit-identically.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use super::CloudParcel;
use crate::error::{Error, Result};

/// The header line, column names in file order.
pub const HEADER: &str = "id,x_m,y_m,z_m,radius_m,fill,cond_plane_z_m";
/// Largest accepted |coordinate| (centre or plane): 10 000 km, beyond any
/// scene; it keeps the renderer's bounding boxes finite. units: m
const MAX_COORD_M: f32 = 1.0e7;
/// Accepted radii: a parcel of under 1 m is not a cloud at the renderer's
/// scale, and one of over 50 km is larger than any convective cell. units: m
const RADIUS_RANGE_M: (f32, f32) = (1.0, 50_000.0);

/// Reads a cloud field written by [`write()`] (or by hand). Every error names
/// the file, line and column, what was wrong and what is allowed.
pub fn read(path: &Path) -> Result<Vec<CloudParcel>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    parse(&text, path)
}

/// Parses the text of a cloud-field file (`path` only names it in errors).
pub fn parse(text: &str, path: &Path) -> Result<Vec<CloudParcel>> {
    let mut parcels = Vec::new();
    let mut seen_header = false;
    let mut ids: HashMap<u64, usize> = HashMap::new();
    for (i, raw) in text.lines().enumerate() {
        let lineno = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if !seen_header {
            let names: Vec<&str> = line.split(',').map(str::trim).collect();
            if names != HEADER.split(',').collect::<Vec<_>>() {
                return Err(Error::parse(
                    path,
                    lineno,
                    1,
                    format!(
                        "header {line:?}: a cloud-field file starts with the line {HEADER:?} (after '#' comments)"
                    ),
                ));
            }
            seen_header = true;
            continue;
        }
        let p = parse_row(raw, path, lineno)?;
        if let Some(first) = ids.insert(p.id, lineno) {
            return Err(Error::parse(
                path,
                lineno,
                1,
                format!(
                    "id {} already used on line {first}: every parcel needs its own id",
                    p.id
                ),
            ));
        }
        parcels.push(p);
    }
    if !seen_header {
        return Err(Error::parse(
            path,
            0,
            0,
            format!("no header: a cloud-field file starts with the line {HEADER:?}"),
        ));
    }
    Ok(parcels)
}

/// One data row → a parcel, every value checked.
fn parse_row(raw: &str, path: &Path, lineno: usize) -> Result<CloudParcel> {
    let names: Vec<&str> = HEADER.split(',').collect();
    let fields: Vec<&str> = raw.split(',').collect();
    if fields.len() != names.len() {
        return Err(Error::parse(
            path,
            lineno,
            1,
            format!(
                "{} values: each row has {} ({HEADER})",
                fields.len(),
                names.len()
            ),
        ));
    }
    // 1-based column of field `k`'s first non-blank character.
    let col = |k: usize| {
        let f = fields[k];
        fields[..k]
            .iter()
            .map(|f| f.chars().count() + 1)
            .sum::<usize>()
            + (f.chars().count() - f.trim_start().chars().count())
            + 1
    };
    let id = fields[0].trim().parse::<u64>().map_err(|_| {
        Error::parse(
            path,
            lineno,
            col(0),
            format!(
                "id {:?}: allowed is a whole number from 0",
                fields[0].trim()
            ),
        )
    })?;
    let mut v = [0.0f32; 6];
    for (k, x) in v.iter_mut().enumerate() {
        let s = fields[k + 1].trim();
        *x = match s.parse::<f32>() {
            Ok(x) if x.is_finite() => x,
            _ => {
                return Err(Error::parse(
                    path,
                    lineno,
                    col(k + 1),
                    format!("{} {s:?}: allowed is a finite number", names[k + 1]),
                ));
            }
        };
    }
    let [x, y, z, radius, fill, plane] = v;
    let check = |ok: bool, k: usize, allowed: &str| {
        if ok {
            Ok(())
        } else {
            Err(Error::parse(
                path,
                lineno,
                col(k),
                format!("{} {}: allowed {allowed}", names[k], fields[k].trim()),
            ))
        }
    };
    let coord = format!("is |value| ≤ {MAX_COORD_M} m");
    for (k, c) in [(1, x), (2, y), (3, z), (6, plane)] {
        check(c.abs() <= MAX_COORD_M, k, &coord)?;
    }
    check(
        (RADIUS_RANGE_M.0..=RADIUS_RANGE_M.1).contains(&radius),
        4,
        &format!("are {} to {} m", RADIUS_RANGE_M.0, RADIUS_RANGE_M.1),
    )?;
    check(
        (0.0..=1.0).contains(&fill),
        5,
        "is a filling ratio from 0 to 1",
    )?;
    Ok(CloudParcel {
        id,
        center_m: Vec3::new(x, y, z),
        radius_m: radius,
        fill,
        cond_plane_z_m: plane,
    })
}

/// The text of a cloud-field file holding `parcels` (`comment` goes on a
/// '#' line above the header).
pub fn to_text(parcels: &[CloudParcel], comment: &str) -> String {
    let mut s = String::new();
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    let _ = writeln!(s, "{HEADER}");
    for p in parcels {
        let c = p.center_m;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{}",
            p.id, c.x, c.y, c.z, p.radius_m, p.fill, p.cond_plane_z_m
        );
    }
    s
}

/// Writes `parcels` to `path`, whole or not at all.
pub fn write(path: &Path, parcels: &[CloudParcel], comment: &str) -> Result<()> {
    crate::output::write_atomic(path, to_text(parcels, comment).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field() -> Vec<CloudParcel> {
        vec![
            CloudParcel {
                id: 7,
                center_m: Vec3::new(-1234.567, 0.1, 1500.25),
                radius_m: 312.3,
                fill: 0.123_456_79,
                cond_plane_z_m: 1100.0,
            },
            CloudParcel {
                id: 9,
                center_m: Vec3::new(1.0e-3, -2.0e4, 9000.0),
                radius_m: 1.0,
                fill: 1.0,
                cond_plane_z_m: -3.5,
            },
        ]
    }

    #[test]
    fn a_written_field_reads_back_bit_identically() {
        let text = to_text(&field(), "two parcels\nfor the test");
        assert_eq!(parse(&text, Path::new("f.csv")).unwrap(), field());
    }

    /// The error for `row` (after the header) names line 3 (a comment, the
    /// header, the row), `col` and `words`.
    fn rejects(row: &str, col: usize, words: &str) {
        let text = format!("# c\n{HEADER}\n{row}\n");
        let e = parse(&text, Path::new("f.csv")).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("f.csv:3:{col}:")) && e.contains(words),
            "{row:?} gave {e:?}"
        );
    }

    #[test]
    fn bad_rows_are_errors_naming_line_column_and_what_is_allowed() {
        rejects("0,0,0,1500,500,1", 1, "6 values");
        rejects("x,0,0,1500,500,1,1100", 1, "whole number");
        rejects(
            "0,0,NaN,1500,500,1,1100",
            5,
            "y_m \"NaN\": allowed is a finite number",
        );
        rejects("0,0,0,inf,500,1,1100", 7, "finite number");
        rejects(
            "0,0,0,1500,0.5,1,1100",
            12,
            "radius_m 0.5: allowed are 1 to 50000 m",
        );
        rejects("0,0,0,1500,500,1.5,1100", 16, "fill 1.5");
        rejects("0,0,0,1500,500,1,2e7", 18, "cond_plane_z_m");
        rejects("0, 0, 0, 1500, 500, -0.1, 1100", 21, "filling ratio");
    }

    #[test]
    fn a_missing_header_or_a_repeated_id_is_an_error() {
        let p = Path::new("f.csv");
        let e = parse("0,0,0,1500,500,1,1100\n", p).unwrap_err().to_string();
        assert!(e.starts_with("f.csv:1:1: header"), "{e}");
        let e = parse("# only a comment\n", p).unwrap_err().to_string();
        assert!(e.contains("no header"), "{e}");
        let two = format!("{HEADER}\n4,0,0,1500,500,1,1100\n4,0,0,2500,500,1,1100\n");
        let e = parse(&two, p).unwrap_err().to_string();
        assert!(
            e.starts_with("f.csv:3:1:") && e.contains("already used on line 2"),
            "{e}"
        );
    }
}
