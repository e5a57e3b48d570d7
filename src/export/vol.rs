//! Mitsuba 3's `gridvolume` binary format (`.vol`), single channel float32:
//!
//! | bytes | content |
//! |---|---|
//! | 0–2 | ASCII `VOL` |
//! | 3 | version, 3 |
//! | 4–7 | encoding, int32: 1 = float32 |
//! | 8–19 | cells along x, y, z, int32 each |
//! | 20–23 | channels, int32 (1 here) |
//! | 24–47 | bounding box min x, y, z, max x, y, z, float32 each |
//! | 48– | values, float32, x fastest: ((z·ny + y)·nx + x)·channels + c |
//!
//! All little-endian. Mitsuba 3 maps the grid onto the unit cube and places
//! it with the volume's `to_world` (or uses this box with `use_grid_bbox`),
//! with value i at the centre of cell i (trilinear between centres).

use std::io::Write;

use crate::error::{Error, Result};

/// Header bytes before the values.
pub const HEADER_BYTES: usize = 48;
/// Encoding identifier of float32 data.
const ENCODING_F32: i32 = 1;

/// A single-channel float32 grid and its world box.
#[derive(Debug, Clone, PartialEq)]
pub struct VolGrid {
    /// Cells along x, y, z.
    pub dims: [u32; 3],
    /// Lowest corner of the box. units: m
    pub min: [f32; 3],
    /// Highest corner of the box. units: m
    pub max: [f32; 3],
    /// Values, x fastest, `dims[0]·dims[1]·dims[2]` of them.
    pub values: Vec<f32>,
}

impl VolGrid {
    /// File size of this grid. units: bytes
    pub fn file_bytes(&self) -> u64 {
        HEADER_BYTES as u64 + 4 * self.values.len() as u64
    }
}

/// Writes `g` in the `.vol` format.
pub fn write_vol(w: &mut dyn Write, g: &VolGrid) -> std::io::Result<()> {
    let n: u64 = g.dims.iter().map(|&d| d as u64).product();
    if n != g.values.len() as u64 {
        return Err(std::io::Error::other(format!(
            "grid {:?} needs {n} values, has {}",
            g.dims,
            g.values.len()
        )));
    }
    let mut head = Vec::with_capacity(HEADER_BYTES);
    head.extend_from_slice(b"VOL");
    head.push(3);
    head.extend_from_slice(&ENCODING_F32.to_le_bytes());
    for d in g.dims {
        head.extend_from_slice(&(d as i32).to_le_bytes());
    }
    head.extend_from_slice(&1i32.to_le_bytes());
    for v in g.min.iter().chain(&g.max) {
        head.extend_from_slice(&v.to_le_bytes());
    }
    w.write_all(&head)?;
    // Values in blocks: one write per 64 Ki values, not per value.
    for block in g.values.chunks(1 << 16) {
        let bytes: Vec<u8> = block.iter().flat_map(|v| v.to_le_bytes()).collect();
        w.write_all(&bytes)?;
    }
    Ok(())
}

/// Reads a single-channel float32 `.vol`; errors name `what` (the file) and
/// the header field that is wrong.
pub fn read_vol(bytes: &[u8], what: &str) -> Result<VolGrid> {
    let bad = |msg: String| Error::parse(what, 0, 0, msg);
    if bytes.len() < HEADER_BYTES {
        return Err(bad(format!(
            "{} bytes: a .vol header is {HEADER_BYTES}",
            bytes.len()
        )));
    }
    if &bytes[..3] != b"VOL" || bytes[3] != 3 {
        return Err(bad(
            "not a version-3 VOL file (bytes 0–3 must be \"VOL\" 3)".into(),
        ));
    }
    let i32_at = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    if i32_at(4) != ENCODING_F32 {
        return Err(bad(format!(
            "encoding {}: only 1 (float32) is read",
            i32_at(4)
        )));
    }
    if i32_at(20) != 1 {
        return Err(bad(format!("{} channels: only 1 is read", i32_at(20))));
    }
    let mut dims = [0u32; 3];
    for (a, d) in dims.iter_mut().enumerate() {
        let v = i32_at(8 + 4 * a);
        if v < 1 {
            return Err(bad(format!("{v} cells along axis {a}: at least 1")));
        }
        *d = v as u32;
    }
    let n: u64 = dims.iter().map(|&d| d as u64).product();
    let want = HEADER_BYTES as u64 + 4 * n;
    if bytes.len() as u64 != want {
        return Err(bad(format!(
            "{} bytes: a {}×{}×{} float32 grid takes {want}",
            bytes.len(),
            dims[0],
            dims[1],
            dims[2]
        )));
    }
    let min = [f32_at(24), f32_at(28), f32_at(32)];
    let max = [f32_at(36), f32_at(40), f32_at(44)];
    let values = bytes[HEADER_BYTES..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    Ok(VolGrid {
        dims,
        min,
        max,
        values,
    })
}
