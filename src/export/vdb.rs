//! OpenVDB (`.vdb`) writer: one float grid named `density`, the standard
//! `Tree_float_5_4_3` tree, file format 224 (OpenVDB 6 and later, the one
//! Blender, Houdini and the OpenVDB tools read).
//!
//! The grid is sparse: only 8³ leaves holding a non-zero value are stored
//! (each voxel ≠ 0 active, the rest inactive at the background 0), under
//! 16³ and 32³ internal nodes with no tiles. Index (i, j, k) is the cell
//! of the dense grid with that index (x, y, z); the transform is a
//! `UniformScaleTranslateMap` putting voxel (i, j, k)'s centre at
//! `min + voxel·(i + ½, j + ½, k + ½)` m, the centre the `.vol` grid
//! samples (OpenVDB places values at index points, Mitsuba at cell centres:
//! the same points). Values are zlib-compressed per node (`COMPRESS_ZIP`,
//! all 512 values of a leaf), as `openvdb::io` writes them.
//!
//! The layout, all little-endian (`openvdb/io/Archive.cc`, `File.cc`,
//! `tree/RootNode.h`, `InternalNode.h`, `LeafNode.h`, `io/Compression.h`):
//!
//! | part | content |
//! |---|---|
//! | header | magic `0x56444220` (i64), file version 224, library version (u32 ×2), has-offsets (u8 = 1), UUID (36 ASCII) |
//! | file metadata | count (u32) and entries: name, type name, size (u32), value |
//! | grids | count (u32); per grid: name, type, instance parent (strings), grid / block / end offsets (i64), compression (u32), metadata, transform, topology, buffers |
//! | topology | buffer count 1, background (f32), tiles 0, root children; per child its origin (i32 ×3), then each internal node: child mask, value mask, its values (compressed), its children in index order; a leaf: its value mask |
//! | buffers | per leaf in tree order: value mask, its 512 values (compressed) |
//!
//! Strings are a u32 length and the bytes. The UUID is derived from the
//! values (FNV-1a), so the same grid writes the same bytes.

use std::collections::BTreeMap;
use std::io::Write;

use super::GridSpec;

/// `OPENVDB_MAGIC`.
const MAGIC: i64 = 0x5644_4220;
/// `OPENVDB_FILE_VERSION_MULTIPASS_IO`, the current format.
const FILE_VERSION: u32 = 224;
/// The library version the header names (informational to readers).
const LIBRARY_VERSION: (u32, u32) = (10, 0);
/// `COMPRESS_ZIP` (without `COMPRESS_ACTIVE_MASK`: every value written).
const COMPRESS_ZIP: u32 = 0x1;
/// Per-node compression metadata `NO_MASK_AND_ALL_VALS`.
const NO_MASK_AND_ALL_VALS: u8 = 6;
/// The grid name renderers look for (Blender's and Houdini's volume
/// shaders read `density`).
pub const GRID_NAME: &str = "density";
const GRID_TYPE: &str = "Tree_float_5_4_3";

/// log2 of the node sides, leaf to root child (8, 16·8 = 128, 32·128 = 4096 voxels).
const LEAF_LOG2: u32 = 3;
const LOWER_LOG2: u32 = 4;
const UPPER_LOG2: u32 = 5;
const LEAF_VALUES: usize = 1 << (3 * LEAF_LOG2);

/// A metadata value OpenVDB knows by type name.
#[derive(Debug, Clone, PartialEq)]
pub enum Meta {
    Str(String),
    Float(f32),
    Int64(i64),
    Vec3i([i32; 3]),
}

/// Writes the dense grid `values` (x fastest, `spec.dims`) as a sparse
/// OpenVDB float grid named [`GRID_NAME`] with `metadata` on the grid
/// (besides the standard `class`, `name` and file bounding box).
pub fn write_vdb(
    w: &mut dyn Write,
    spec: &GridSpec,
    values: &[f32],
    metadata: &[(&str, Meta)],
) -> std::io::Result<()> {
    if spec.cells() != values.len() as u64 {
        return Err(std::io::Error::other(format!(
            "grid {:?} needs {} values, has {}",
            spec.dims,
            spec.cells(),
            values.len()
        )));
    }
    let leaves = leaves(spec, values);
    let active: i64 = leaves.values().map(|l| l.mask.count() as i64).sum();

    let mut meta = vec![
        ("class", Meta::Str("fog volume".into())),
        ("name", Meta::Str(GRID_NAME.into())),
        ("file_voxel_count", Meta::Int64(active)),
    ];
    if let Some((lo, hi)) = active_bounds(&leaves) {
        meta.push(("file_bbox_min", Meta::Vec3i(lo)));
        meta.push(("file_bbox_max", Meta::Vec3i(hi)));
    }
    meta.extend(metadata.iter().cloned());

    let mut file = Vec::new();
    // Header.
    file.extend_from_slice(&MAGIC.to_le_bytes());
    put_u32(&mut file, FILE_VERSION);
    put_u32(&mut file, LIBRARY_VERSION.0);
    put_u32(&mut file, LIBRARY_VERSION.1);
    file.push(1); // grid offsets follow each descriptor
    file.extend_from_slice(uuid(values).as_bytes());
    put_meta(&mut file, &[("creator", Meta::Str("cumulus".into()))]);
    put_u32(&mut file, 1); // one grid

    // Grid descriptor; its three offsets are patched once known.
    put_str(&mut file, GRID_NAME);
    put_str(&mut file, GRID_TYPE);
    put_str(&mut file, ""); // not an instance
    let offsets_at = file.len();
    file.extend_from_slice(&[0u8; 24]);
    let grid_pos = file.len() as u64;
    put_u32(&mut file, COMPRESS_ZIP);
    put_meta(&mut file, &meta);
    put_transform(&mut file, spec);
    put_topology(&mut file, &leaves)?;
    let block_pos = file.len() as u64;
    for leaf in leaves.values() {
        put_mask(&mut file, &leaf.mask.0);
        put_values(&mut file, &leaf.values)?;
    }
    let end_pos = file.len() as u64;
    for (i, pos) in [grid_pos, block_pos, end_pos].into_iter().enumerate() {
        let at = offsets_at + 8 * i;
        file[at..at + 8].copy_from_slice(&pos.to_le_bytes());
    }
    w.write_all(&file)
}

/// A bit mask of `n` bits stored as u64 words (`util::NodeMask`).
#[derive(Debug, Clone)]
struct Mask(Vec<u64>);

impl Mask {
    fn new(log2: u32) -> Self {
        Self(vec![0; (1usize << (3 * log2)) / 64])
    }
    fn set(&mut self, n: usize) {
        self.0[n / 64] |= 1 << (n % 64);
    }
    fn count(&self) -> u32 {
        self.0.iter().map(|w| w.count_ones()).sum()
    }
}

/// A stored leaf: its active voxels and its 512 values.
struct Leaf {
    origin: [i32; 3],
    mask: Mask,
    values: Vec<f32>,
}

/// Key ordering leaves as the tree stores them: root child by origin, then
/// the lower node's index in it, then the leaf's index in that.
type TreeKey = ([i32; 3], usize, usize);

/// Index of the child containing `xyz` in a node of side 2^`log2` children
/// each 2^`child_total` voxels wide (x slowest, z fastest).
fn child_index(xyz: [i32; 3], log2: u32, child_total: u32) -> usize {
    let mask = (1 << log2) - 1;
    let [x, y, z] = xyz.map(|c| ((c >> child_total) & mask) as usize);
    (x << (2 * log2)) | (y << log2) | z
}

fn tree_key(origin: [i32; 3]) -> TreeKey {
    let upper_total = LOWER_LOG2 + LEAF_LOG2;
    let root_side = UPPER_LOG2 + upper_total;
    (
        origin.map(|c| c >> root_side << root_side),
        child_index(origin, UPPER_LOG2, upper_total),
        child_index(origin, LOWER_LOG2, LEAF_LOG2),
    )
}

/// The 8³ blocks of the dense grid that hold a non-zero value.
fn leaves(spec: &GridSpec, values: &[f32]) -> BTreeMap<TreeKey, Leaf> {
    let [nx, ny, nz] = spec.dims.map(|d| d as usize);
    let side = 1usize << LEAF_LOG2;
    let mut out = BTreeMap::new();
    for bz in (0..nz).step_by(side) {
        for by in (0..ny).step_by(side) {
            for bx in (0..nx).step_by(side) {
                let mut leaf = Leaf {
                    origin: [bx as i32, by as i32, bz as i32],
                    mask: Mask::new(LEAF_LOG2),
                    values: vec![0.0; LEAF_VALUES],
                };
                for z in bz..(bz + side).min(nz) {
                    for y in by..(by + side).min(ny) {
                        for x in bx..(bx + side).min(nx) {
                            let v = values[(z * ny + y) * nx + x];
                            if v != 0.0 {
                                let n = ((x - bx) << (2 * LEAF_LOG2))
                                    | ((y - by) << LEAF_LOG2)
                                    | (z - bz);
                                leaf.values[n] = v;
                                leaf.mask.set(n);
                            }
                        }
                    }
                }
                if leaf.mask.count() > 0 {
                    out.insert(tree_key(leaf.origin), leaf);
                }
            }
        }
    }
    out
}

/// Index bounds of the stored leaves (OpenVDB's `file_bbox_*`, which
/// `evalActiveVoxelBoundingBox` gives at leaf resolution for this tree).
fn active_bounds(leaves: &BTreeMap<TreeKey, Leaf>) -> Option<([i32; 3], [i32; 3])> {
    let side = 1 << LEAF_LOG2;
    leaves.values().fold(None, |acc, l| {
        let hi = l.origin.map(|c| c + side - 1);
        Some(match acc {
            None => (l.origin, hi),
            Some((a, b)) => (
                [0, 1, 2].map(|i| a[i].min(l.origin[i])),
                [0, 1, 2].map(|i| b[i].max(hi[i])),
            ),
        })
    })
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_str(out: &mut Vec<u8>, s: &str) {
    put_u32(out, s.len() as u32);
    out.extend_from_slice(s.as_bytes());
}

/// `MetaMap::writeMeta`: count, then name, type name, size, value.
fn put_meta(out: &mut Vec<u8>, meta: &[(&str, Meta)]) {
    put_u32(out, meta.len() as u32);
    for (name, value) in meta {
        put_str(out, name);
        let (type_name, bytes): (&str, Vec<u8>) = match value {
            Meta::Str(s) => ("string", s.as_bytes().to_vec()),
            Meta::Float(f) => ("float", f.to_le_bytes().to_vec()),
            Meta::Int64(i) => ("int64", i.to_le_bytes().to_vec()),
            Meta::Vec3i(v) => ("vec3i", v.iter().flat_map(|c| c.to_le_bytes()).collect()),
        };
        put_str(out, type_name);
        put_u32(out, bytes.len() as u32);
        out.extend_from_slice(&bytes);
    }
}

/// `UniformScaleTranslateMap::write`: translation, scale, voxel size,
/// 1/scale, 1/scale², 1/(2·scale), each three f64.
fn put_transform(out: &mut Vec<u8>, spec: &GridSpec) {
    put_str(out, "UniformScaleTranslateMap");
    let v = spec.voxel_m as f64;
    let centre0 = spec.min.as_dvec3() + glam::DVec3::splat(0.5 * v);
    for vec in [
        centre0,
        glam::DVec3::splat(v),
        glam::DVec3::splat(v),
        glam::DVec3::splat(1.0 / v),
        glam::DVec3::splat(1.0 / (v * v)),
        glam::DVec3::splat(0.5 / v),
    ] {
        for c in vec.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
}

fn put_mask(out: &mut Vec<u8>, words: &[u64]) {
    for w in words {
        out.extend_from_slice(&w.to_le_bytes());
    }
}

/// `io::writeCompressedValues` with `COMPRESS_ZIP`: the metadata byte, the
/// zlib stream's size (i64), the stream.
fn put_values(out: &mut Vec<u8>, values: &[f32]) -> std::io::Result<()> {
    out.push(NO_MASK_AND_ALL_VALS);
    let raw: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw)?;
    let zipped = z.finish()?;
    out.extend_from_slice(&(zipped.len() as i64).to_le_bytes());
    out.extend_from_slice(&zipped);
    Ok(())
}

/// `Tree::writeTopology`: buffer count, background, no tiles, the root's
/// children (32³ nodes) with their 16³ children and those's leaf masks.
fn put_topology(out: &mut Vec<u8>, leaves: &BTreeMap<TreeKey, Leaf>) -> std::io::Result<()> {
    put_u32(out, 1);
    out.extend_from_slice(&0f32.to_le_bytes());
    // Group the (already tree-ordered) leaves by root child, then lower node.
    let mut roots: BTreeMap<[i32; 3], BTreeMap<usize, Vec<&Leaf>>> = BTreeMap::new();
    for ((root, lower, _), leaf) in leaves {
        roots
            .entry(*root)
            .or_default()
            .entry(*lower)
            .or_default()
            .push(leaf);
    }
    put_u32(out, 0);
    put_u32(out, roots.len() as u32);
    for (origin, lowers) in &roots {
        for c in origin {
            out.extend_from_slice(&c.to_le_bytes());
        }
        let mut children = Mask::new(UPPER_LOG2);
        lowers.keys().for_each(|&i| children.set(i));
        put_internal(out, &children, UPPER_LOG2)?;
        for lower in lowers.values() {
            let mut children = Mask::new(LOWER_LOG2);
            for leaf in lower {
                children.set(child_index(leaf.origin, LOWER_LOG2, LEAF_LOG2));
            }
            put_internal(out, &children, LOWER_LOG2)?;
            for leaf in lower {
                put_mask(out, &leaf.mask.0);
            }
        }
    }
    Ok(())
}

/// `InternalNode::writeTopology`'s own part: child mask, value mask (no
/// active tiles), the tile values (all background).
fn put_internal(out: &mut Vec<u8>, children: &Mask, log2: u32) -> std::io::Result<()> {
    put_mask(out, &children.0);
    put_mask(out, &Mask::new(log2).0);
    put_values(out, &vec![0.0; 1 << (3 * log2)])
}

/// A version-4-shaped UUID string from an FNV-1a-style hash of the values'
/// bits (two lanes), so the same grid writes the same bytes.
fn uuid(values: &[f32]) -> String {
    let mut h: [u64; 2] = [0xcbf2_9ce4_8422_2325, 0x8422_2325_cbf2_9ce4];
    for v in values {
        for (k, x) in h.iter_mut().enumerate() {
            *x = (*x ^ (v.to_bits() as u64 + k as u64)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    let hex = format!("{:016x}{:016x}", h[0], h[1]);
    format!(
        "{}-{}-4{}-a{}-{}",
        &hex[0..8],
        &hex[8..12],
        &hex[13..16],
        &hex[17..20],
        &hex[20..32]
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn leaves_are_ordered_as_the_tree_stores_them() {
        // (0, 200, 0) sits in the lower node at y = 128, after every leaf
        // of the lower node at the origin, although its x is smaller.
        assert!(tree_key([8, 0, 0]) < tree_key([0, 200, 0]));
        assert!(tree_key([0, 0, 8]) < tree_key([0, 8, 0]));
        assert!(tree_key([4088, 0, 0]) < tree_key([4096, 0, 0]));
        assert_eq!(child_index([8, 0, 0], LOWER_LOG2, LEAF_LOG2), 256);
        assert_eq!(child_index([0, 0, 128], UPPER_LOG2, 7), 1);
    }

    #[test]
    fn only_blocks_with_cloud_are_stored() {
        let spec = GridSpec::covering(Vec3::ZERO, Vec3::new(20.0, 10.0, 9.0), 1.0, 1).unwrap();
        let mut values = vec![0.0; spec.cells() as usize];
        values[(3 * 10 + 9) * 20 + 17] = 0.5; // x 17, y 9, z 3: block (16, 8, 0)
        let l = leaves(&spec, &values);
        assert_eq!(l.len(), 1);
        let leaf = l.values().next().unwrap();
        assert_eq!(leaf.origin, [16, 8, 0]);
        assert_eq!(leaf.mask.count(), 1);
        assert_eq!(leaf.values[(1 << 6) | (1 << 3) | 3], 0.5);
        assert_eq!(active_bounds(&l), Some(([16, 8, 0], [23, 15, 7])));
    }

    #[test]
    fn the_same_grid_writes_the_same_bytes() {
        let spec = GridSpec::covering(Vec3::ZERO, Vec3::splat(12.0), 1.0, 1).unwrap();
        let values: Vec<f32> = (0..spec.cells()).map(|i| (i % 7) as f32 * 0.1).collect();
        let write = |v: &[f32]| {
            let mut out = Vec::new();
            write_vdb(&mut out, &spec, v, &[]).unwrap();
            out
        };
        let a = write(&values);
        assert_eq!(a, write(&values));
        assert_eq!(&a[..8], &MAGIC.to_le_bytes());
        let mut other = values.clone();
        other[5] = 0.9;
        assert_ne!(a, write(&other), "the UUID and the values follow the grid");
        assert!(write_vdb(&mut Vec::new(), &spec, &values[1..], &[]).is_err());
    }
}
