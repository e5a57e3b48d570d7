//! Error against the path tracer: reads `error_vs_pathtraced.csv`, written
//! by benches/pathtraced.py (Mitsuba 3 `volpath` on the `cumulus export`
//! grid of a fixed frame), when it sits in the bench's output folder, so the
//! report and the error plot show it beside the internal sweep.
//! Columns: `setting,time_ms,mean_flip,rmse`; the row `pathtraced` is the
//! path tracer itself (its render time, error 0).

use std::path::Path;

use serde::Deserialize;

use crate::error::{Error, Result};

/// File name the bench looks for in its output folder.
pub const FILE: &str = "error_vs_pathtraced.csv";

/// One row: a setting of our renderer against the path tracer.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PathTracedRow {
    pub setting: String,
    /// Frame time (ours: upload + passes; the path tracer: wall clock). units: ms
    pub time_ms: f64,
    /// Mean FLIP against the path-traced picture (0 = identical).
    pub mean_flip: f64,
    /// RMSE of display sRGB values on 0..1.
    pub rmse: f64,
}

/// The rows of `dir/error_vs_pathtraced.csv`, or None when there is none;
/// a malformed file is an error naming its line.
pub fn read(dir: &Path) -> Result<Option<Vec<PathTracedRow>>> {
    let path = dir.join(FILE);
    if !path.exists() {
        return Ok(None);
    }
    let mut r = csv::Reader::from_path(&path)
        .map_err(|e| Error::io(&path, std::io::Error::other(e.to_string())))?;
    let mut rows = Vec::new();
    for (i, rec) in r.deserialize::<PathTracedRow>().enumerate() {
        // Line i + 2: the header is line 1.
        let row = rec.map_err(|e| {
            Error::parse(
                &path,
                i + 2,
                0,
                format!("{e}: expected setting,time_ms,mean_flip,rmse with numbers"),
            )
        })?;
        if !(row.mean_flip.is_finite() && row.rmse.is_finite() && row.time_ms.is_finite()) {
            return Err(Error::parse(&path, i + 2, 0, "non-finite number"));
        }
        rows.push(row);
    }
    Ok(Some(rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rows_and_names_a_bad_line() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(read(dir.path()).unwrap(), None);
        std::fs::write(
            dir.path().join(FILE),
            "setting,time_ms,mean_flip,rmse\npathtraced,900,0,0\ndefault,12.5,0.08,0.05\n",
        )
        .unwrap();
        let rows = read(dir.path()).unwrap().unwrap();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1].setting, "default");
        assert_eq!(rows[1].mean_flip, 0.08);
        std::fs::write(
            dir.path().join(FILE),
            "setting,time_ms,mean_flip,rmse\ndefault,x,0.08,0.05\n",
        )
        .unwrap();
        let e = read(dir.path()).unwrap_err().to_string();
        assert!(e.contains(":2") && e.contains(FILE), "{e}");
    }
}
