//! Density grids of heterogeneous media (`[media.NAME] grid = "file.vdb"`): an OpenVDB file's
//! float grid, read with the `vdb-rs` crate, resampled into a dense array over the bounding
//! box of its active values, with a coarse majorant grid beside it (the kernel's side:
//! `shaders/media/grid.wgsl`, mirror `src/cpu/media/grid.rs`).
//!
//! The dense array covers the voxels of the box around the active values, and the volume
//! that bounds the medium (`[[volumes]]`) is that box: outside it the density is zero, inside
//! it lookups are trilinear between voxel centres and clamp to the outer voxels within half a
//! voxel of the box's faces (so a constant grid is exactly a homogeneous box). Voxel (i, j, k)
//! of the array has its centre at continuous grid coordinates (i + ½, j + ½, k + ½); the array
//! covers [0, dims]. Inactive voxels count as zero (the grid's background is not read: a fog
//! volume's is 0).

use glam::{IVec3, Mat4, Vec3};
use std::io::Cursor;
use std::path::Path;

/// The most voxels a dense grid may have: 2²⁵ f32 voxels are 128 MiB, lavapipe's largest
/// storage binding, which also holds the majorants.
pub const MAX_GRID_VOXELS: u64 = (1 << 25) - (1 << 20);

/// The largest factor a grid is averaged down by to fit [`MAX_GRID_VOXELS`]: beyond it, so
/// much detail would go that the file is refused instead.
pub const MAX_DOWNSAMPLE: u32 = 4;

/// Voxels per edge of a majorant block (`GridMedium::block`).
pub const MAJORANT_BLOCK: u32 = 8;

/// The largest density a grid may hold (times the medium's coefficients, within
/// `MAX_COEFFICIENT`'s range).
pub const MAX_DENSITY: f32 = 1e6;

/// A dense density grid: `dims` voxels, x fastest (`density[x + dims.x (y + dims.y z)]`),
/// and where it lies in the grid's own space (the file's "world" space, before the volume's
/// transform).
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    /// The file and grid it came from, for messages.
    pub source: String,
    pub dims: [u32; 3],
    pub density: Vec<f32>,
    /// Continuous grid coordinates (voxel i's centre at i + ½) to the grid's own space.
    pub grid_to_object: Mat4,
    /// 1 when the file's voxels are these; f when each of these is the mean of f³ of the
    /// file's (a grid too large for one binding, [`MAX_GRID_VOXELS`]).
    pub downsampled: u32,
    /// The size of the file's grid around its active values, before any downsampling.
    pub read_dims: [u32; 3],
}

impl DensityGrid {
    /// The largest density in the grid.
    pub fn max_density(&self) -> f32 {
        self.density.iter().copied().fold(0.0, f32::max)
    }

    /// The majorant blocks along each axis.
    pub fn block_dims(&self) -> [u32; 3] {
        self.dims.map(|d| d.div_ceil(MAJORANT_BLOCK))
    }

    /// The largest density that trilinear lookups can return in each block: the maximum over
    /// its voxels and the ring of voxels around it (a lookup interpolates between a voxel and
    /// its neighbours). x fastest, as the density.
    pub fn majorants(&self) -> Vec<f32> {
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        let [bx, by, bz] = self.block_dims();
        let b = MAJORANT_BLOCK as i64;
        let mut out = Vec::with_capacity((bx * by * bz) as usize);
        for k in 0..bz as i64 {
            for j in 0..by as i64 {
                for i in 0..bx as i64 {
                    let mut m = 0.0f32;
                    for z in (k * b - 1).max(0)..((k + 1) * b + 1).min(nz) {
                        for y in (j * b - 1).max(0)..((j + 1) * b + 1).min(ny) {
                            let row = ((z * ny + y) * nx) as usize;
                            for x in (i * b - 1).max(0)..((i + 1) * b + 1).min(nx) {
                                m = m.max(self.density[row + x as usize]);
                            }
                        }
                    }
                    out.push(m);
                }
            }
        }
        out
    }

    /// The corners of the box in the scene, under `placement`.
    /// Whether `p` lies strictly inside the box [`DensityGrid::corners`] spans.
    pub fn box_contains(&self, placement: &Mat4, p: Vec3) -> bool {
        let to_grid = (*placement * self.grid_to_object).inverse();
        let q = to_grid.transform_point3(p);
        let d = Vec3::from(self.dims.map(|d| d as f32));
        q.is_finite() && q.cmpgt(Vec3::ZERO).all() && q.cmplt(d).all()
    }

    pub fn corners(&self, placement: &Mat4) -> [Vec3; 8] {
        let d = Vec3::from(self.dims.map(|d| d as f32));
        std::array::from_fn(|c| {
            let p = Vec3::new(
                if c & 1 != 0 { d.x } else { 0.0 },
                if c & 2 != 0 { d.y } else { 0.0 },
                if c & 4 != 0 { d.z } else { 0.0 },
            );
            placement.transform_point3(self.grid_to_object.transform_point3(p))
        })
    }
}

/// Reads the float grid `grid_name` of the OpenVDB file at `path` into a dense grid. The
/// error is a sentence naming what is wrong (the caller names the file and field).
pub fn read_density_grid(path: &Path, grid_name: &str) -> Result<DensityGrid, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    parse_density_grid(&bytes, grid_name, &path.display().to_string())
}

/// [`read_density_grid`] from the file's bytes; `shown` names it in messages.
pub fn parse_density_grid(
    bytes: &[u8],
    grid_name: &str,
    shown: &str,
) -> Result<DensityGrid, String> {
    // OpenVDB's magic number, 0x56444220 (" BDV") as a little-endian 64-bit integer: vdb-rs
    // does not check it.
    if bytes.len() < 8 || bytes[..8] != [0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0] {
        return Err(format!(
            "{shown} is not an OpenVDB file (it does not start with the VDB magic number)"
        ));
    }
    // The byte after the magic and three versions says whether the grids' stream positions
    // follow their descriptors: OpenVDB writes them to files, not to streams (Blender's
    // geometry node bakes write their volumes so), and vdb-rs reads only the former.
    if bytes.len() > 20 && bytes[20] == 0 {
        return Err(format!(
            "{shown} is an OpenVDB stream without grid offsets (as Blender's geometry node \
             bakes write volumes), which glint's reader cannot read: save the grid as a VDB \
             file (OpenVDB's io::File, as Blender's fluid caches and most tools write)"
        ));
    }
    // vdb-rs panics (asserts, unimplemented versions, unwraps) on some files it cannot read,
    // truncated or broken ones among them: a panic there is a broken file, not a crash, and
    // its message is not printed (the error below says what is wrong).
    let parsed = quietly(|| read_with_vdb_rs(bytes, grid_name, shown));
    match parsed {
        Ok(result) => result,
        Err(_) => Err(format!(
            "{shown} is a broken or unsupported OpenVDB file (the reader failed on it; it \
             reads files of OpenVDB 2.1 and later whose grids have a scale and translation \
             transform)"
        )),
    }
}

thread_local! {
    /// Set while this thread runs the reader under [`quietly`].
    static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f`, catching a panic, whose message the panic hook then leaves out (on this thread
/// only: other threads' panics print as before).
fn quietly<T>(f: impl FnOnce() -> T + std::panic::UnwindSafe) -> std::thread::Result<T> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(|q| q.get()) {
                previous(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let result = std::panic::catch_unwind(f);
    QUIET.with(|q| q.set(false));
    result
}

/// The grid types glint reads: 32-bit float grids, also those saved as half floats (the
/// grid's `is_saved_as_half_float` metadata, which is what the reader goes by; OpenVDB's
/// `io::File` then also appends [`HALF_FLOAT_SUFFIX`] to the type name, as in Blender's
/// fluid caches).
const FLOAT_GRID: &str = "Tree_float_5_4_3";

/// What OpenVDB appends to a grid's type name when it saves the grid as half floats.
const HALF_FLOAT_SUFFIX: &str = "_HalfFloat";

/// The smallest factor f (at most [`MAX_DOWNSAMPLE`]) such that the grid of `size` voxels
/// averaged over f³ blocks fits one binding: 1 when it fits as it is.
fn downsample_factor(size: glam::I64Vec3) -> Option<i64> {
    (1..=MAX_DOWNSAMPLE as i64).find(|&f| {
        let c = (size + glam::I64Vec3::splat(f - 1)) / f;
        (c.x as u64)
            .saturating_mul(c.y as u64)
            .saturating_mul(c.z as u64)
            <= MAX_GRID_VOXELS
    })
}

/// The dense grid of `dims` voxels, each the mean density of the `factor`³ fine voxels it
/// covers (a box filter: the medium's mass, ∫ density, is kept), from the active `values`
/// (origin, tile side, density) of a grid whose lowest active voxel is `lo`. Each value adds
/// to the coarse voxels its tile overlaps in proportion to the overlap, so a large tile costs
/// the coarse voxels it covers, not its fine ones.
fn box_filtered(
    values: impl Iterator<Item = (IVec3, i32, f32)>,
    lo: IVec3,
    dims: [u32; 3],
    factor: i64,
) -> Vec<f32> {
    let mut density = vec![0.0f32; dims.iter().map(|&d| d as usize).product()];
    let per_fine = 1.0 / (factor * factor * factor) as f32;
    // The coarse cells a run [start, start + side) of fine voxels overlaps, and by how much.
    let overlaps = |start: i64, side: i64| {
        let first = start / factor;
        let last = (start + side - 1) / factor;
        (first..=last).map(move |c| {
            let covered = (start + side).min((c + 1) * factor) - start.max(c * factor);
            (c as usize, covered as f32)
        })
    };
    for (origin, side, value) in values {
        let o = (origin - lo).as_i64vec3();
        let side = side as i64;
        for (z, wz) in overlaps(o.z, side) {
            for (y, wy) in overlaps(o.y, side) {
                let row = (z * dims[1] as usize + y) * dims[0] as usize;
                for (x, wx) in overlaps(o.x, side) {
                    density[row + x] += value * (wx * wy * wz * per_fine);
                }
            }
        }
    }
    density
}

fn read_with_vdb_rs(bytes: &[u8], grid_name: &str, shown: &str) -> Result<DensityGrid, String> {
    let broken = |e: vdb_rs::ParseError| format!("{shown} is a broken OpenVDB file: {e:?}");
    let mut reader = vdb_rs::VdbReader::new(Cursor::new(bytes)).map_err(broken)?;
    let Some(descriptor) = reader.grid_descriptors.get(grid_name) else {
        let mut names: Vec<_> = reader
            .grid_descriptors
            .iter()
            .map(|(n, d)| format!("{n:?} ({})", d.grid_type))
            .collect();
        names.sort();
        return Err(format!(
            "{shown} has no grid named {grid_name:?}; its grids: {}",
            if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            }
        ));
    };
    let grid_type = descriptor.grid_type.as_str();
    if grid_type != FLOAT_GRID && grid_type.strip_suffix(HALF_FLOAT_SUFFIX) != Some(FLOAT_GRID) {
        return Err(format!(
            "grid {grid_name:?} of {shown} is of type {}, which glint cannot read as a density: \
             it reads float grids ({FLOAT_GRID}, also saved as half floats: \
             {FLOAT_GRID}{HALF_FLOAT_SUFFIX})",
            descriptor.grid_type
        ));
    }
    // The reader goes by the metadata, OpenVDB by the type name; OpenVDB writes both.
    if grid_type != FLOAT_GRID && !descriptor.meta_data.is_half_float() {
        return Err(format!(
            "grid {grid_name:?} of {shown} is of type {grid_type} but lacks the \
             is_saved_as_half_float metadata OpenVDB writes with it, which glint's reader needs \
             to read its half floats"
        ));
    }
    if !descriptor.instance_parent.is_empty() {
        return Err(format!(
            "grid {grid_name:?} of {shown} is an instance of grid {:?}: glint reads grids that \
             hold their own tree",
            descriptor.instance_parent
        ));
    }
    let grid = reader.read_grid::<f32>(grid_name).map_err(broken)?;
    // vdb-rs's glam is not glint's: by components.
    let (size, offset) = match &grid.transform {
        vdb_rs::Map::UniformScaleMap { voxel_size, .. } => {
            ([voxel_size.x, voxel_size.y, voxel_size.z], [0.0; 3])
        }
        vdb_rs::Map::ScaleTranslateMap {
            voxel_size,
            translation,
            ..
        } => (
            [voxel_size.x, voxel_size.y, voxel_size.z],
            [translation.x, translation.y, translation.z],
        ),
    };
    let voxel_size = Vec3::from(size.map(|v| v as f32));
    let translation = Vec3::from(offset.map(|v| v as f32));
    if !voxel_size.is_finite() || voxel_size.min_element() <= 0.0 || !translation.is_finite() {
        return Err(format!(
            "grid {grid_name:?} of {shown} has a degenerate transform (voxel size {voxel_size}, \
             translation {translation})"
        ));
    }
    // The active values: voxels, and tiles of 8³ and 128³ voxels.
    // Two passes over the tree: this one checks the values and bounds them, the fill below
    // reads them again (a large grid's values need not all be held at once).
    let active = || {
        grid.iter()
            .filter(|(_, value, _)| *value != 0.0)
            .map(|(at, value, level)| {
                // vdb-rs's glam is not glint's: by components.
                let origin = IVec3::new(at.x as i32, at.y as i32, at.z as i32);
                (origin, level.scale() as i32, value)
            })
    };
    let mut lo = IVec3::MAX;
    let mut hi = IVec3::MIN;
    for (at, value, _) in grid.iter() {
        if !value.is_finite() {
            return Err(format!(
                "grid {grid_name:?} of {shown} holds a density that is not finite ({value}) at \
                 voxel {:?}",
                [at.x, at.y, at.z]
            ));
        }
        if value < 0.0 {
            return Err(format!(
                "grid {grid_name:?} of {shown} holds a negative density ({value}) at voxel {:?}: \
                 densities must be ≥ 0",
                [at.x, at.y, at.z]
            ));
        }
        if value > MAX_DENSITY {
            return Err(format!(
                "grid {grid_name:?} of {shown} holds a density of {value} at voxel {:?}, above \
                 the {MAX_DENSITY:e} glint accepts (scale the medium's coefficients instead)",
                [at.x, at.y, at.z]
            ));
        }
    }
    for (origin, side, _) in active() {
        lo = lo.min(origin);
        hi = hi.max(origin + IVec3::splat(side - 1));
    }
    if lo.x > hi.x {
        return Err(format!(
            "grid {grid_name:?} of {shown} has no positive density: the medium would be empty"
        ));
    }
    let size = (hi - lo).as_i64vec3() + glam::I64Vec3::splat(1);
    let fine_voxels = size.x as u64 * size.y as u64 * size.z as u64;
    let Some(factor) = downsample_factor(size) else {
        return Err(format!(
            "grid {grid_name:?} of {shown} spans {} × {} × {} voxels around its active values \
             ({:.0} MiB as 32-bit floats), more than the {} MiB one GPU binding holds even \
             averaged over {MAX_DOWNSAMPLE}³ blocks; resample it coarser (a larger voxel size) \
             before rendering",
            size.x,
            size.y,
            size.z,
            fine_voxels as f64 * 4.0 / (1u64 << 20) as f64,
            (MAX_GRID_VOXELS * 4) >> 20
        ));
    };
    let coarse = (size + glam::I64Vec3::splat(factor - 1)) / factor;
    let dims = [coarse.x as u32, coarse.y as u32, coarse.z as u32];
    let density = box_filtered(active(), lo, dims, factor);
    // VDB voxel v's centre is at v · voxel_size + translation; fine voxel i is VDB voxel
    // i + lo, its centre at continuous coordinate i + ½, and coarse voxel j spans fine
    // coordinates [f j, f (j + 1)).
    let grid_to_object = Mat4::from_translation(translation)
        * Mat4::from_scale(voxel_size)
        * Mat4::from_translation(lo.as_vec3() - Vec3::splat(0.5))
        * Mat4::from_scale(Vec3::splat(factor as f32));
    Ok(DensityGrid {
        source: format!("{shown}:{grid_name}"),
        dims,
        density,
        grid_to_object,
        downsampled: factor as u32,
        read_dims: [size.x as u32, size.y as u32, size.z as u32],
    })
}
