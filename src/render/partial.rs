//! Partial render files: an EXR whose RGB channels are the mean radiance (so any EXR viewer
//! opens it as the image), with the per-pixel M2 in the channels `M2.R`, `M2.G`, `M2.B` and,
//! in header attributes, everything a merge or a resume needs: the sample ranges it holds, the
//! range it was asked for, the render's total spp, the seed, and a hash of the scene and of
//! every setting that changes the image. Every EXR `glint render` writes is one, so any EXR
//! render, interrupted or not, can be resumed or merged.
//!
//! Two versions: `glint-partial/1`, where every pixel holds every sample of the ranges, and
//! `glint-partial/2`, written only where adaptive sampling stopped some pixels early, which
//! adds each pixel's own sample count as the 32-bit unsigned channel `N`. Version 1 stays what
//! it was, so glint of before adaptive sampling reads it; it refuses version 2 by its
//! `glint.format`, rather than misread the counts. This glint reads both.

use crate::kernel::types::{Params, PROJECTION_PERSPECTIVE};
use crate::kernel::KernelScene;
use crate::render::accumulation::Accumulation;
use crate::render::adaptive::Adaptive;
use crate::scene::{MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE};
use anyhow::{Context, Result};
use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Layer, LayerAttributes,
    ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
};
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::ops::Range;
use std::path::Path;

/// The format version of files where every pixel holds every sample of its ranges.
pub const FORMAT: &str = "glint-partial/1";
/// The format version of files with per-pixel sample counts (the channel [`COUNT_CHANNEL`]);
/// a reader refuses any version but these two.
pub const FORMAT_COUNTS: &str = "glint-partial/2";
/// Each pixel's own sample count, in version 2.
const COUNT_CHANNEL: &str = "N";
const MEAN_CHANNELS: [&str; 3] = ["R", "G", "B"];
const M2_CHANNELS: [&str; 3] = ["M2.R", "M2.G", "M2.B"];
/// Bidirectional renders: the camera strategies' own mean (RGB holds the image, splats
/// added), and the splat film's 64-bit sums as two 32-bit unsigned words per channel. Their
/// M2 channels hold the sum of squares between batch means, over the batches the header's
/// `glint.batches` says (`src/render/batch_means.rs`).
const CAMERA_CHANNELS: [&str; 3] = ["Camera.R", "Camera.G", "Camera.B"];
const SPLAT_CHANNELS: [[&str; 2]; 3] = [
    ["Splat.R.high", "Splat.R.low"],
    ["Splat.G.high", "Splat.G.low"],
    ["Splat.B.high", "Splat.B.low"],
];

/// What a partial file says about its samples, besides the pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialInfo {
    /// Global sample indices held, sorted and disjoint (one range unless merged with gaps).
    pub ranges: Vec<Range<u32>>,
    /// The range the render was asked to cover (`--samples`, `--shard`); a resume goes on to
    /// its end.
    pub target: Range<u32>,
    /// The full render's samples per pixel: merged partials must cover 0..spp.
    pub spp: u32,
    pub seed: u32,
    /// [`settings_hash`] of the scene the samples are of.
    pub settings: String,
    /// The scene file's path, for messages only.
    pub scene: String,
    /// The device(s) that rendered it, for information only.
    pub device: String,
    /// Adaptive sampling's settings, where it was on (`glint.adaptive`): a resume goes on
    /// with them.
    pub adaptive: Option<Adaptive>,
}

impl PartialInfo {
    /// Samples per pixel held.
    pub fn count(&self) -> u64 {
        self.ranges.iter().map(|r| (r.end - r.start) as u64).sum()
    }
}

/// A partial file's contents.
#[derive(Clone, Debug, PartialEq)]
pub struct Partial {
    pub info: PartialInfo,
    pub accumulation: Accumulation,
}

/// A hash of everything that decides the image besides the sample range: the kernel's view
/// of the scene (camera, size, bounces, seed, light sampling, roulette, every object and
/// material, textures, the environment map, the lights), with the per-batch sample fields cleared. The
/// arrays' bytes are hashed (exact, and fast for maps of millions of texels). The
/// destructuring names every field, so a field added later fails to compile until it is
/// hashed or said not to matter. The BVH is left out: it is derived from the primitives, its
/// build time differs from run to run, and it does not change what a path sees.
pub fn settings_hash(scene: &KernelScene) -> String {
    let KernelScene {
        params,
        spheres,
        quads,
        materials,
        emitters,
        triangles,
        triangle_normals,
        bvh_nodes: _,
        bvh_primitives: _,
        bvh_wide_nodes: _,
        bvh_build_seconds: _,
        textures,
        texels,
        triangle_uvs,
        triangle_uvs1,
        triangle_tangents,
        triangle_colors,
        environment_texels,
        environment_alias,
        lights,
        instances,
        grids,
        grid_voxels,
        light_tree_nodes,
        light_tree_trails,
    } = scene;
    let mut params = *params;
    params.sample_start = 0;
    params.sample_count = 0;
    params.accumulated_samples = 0;
    let mut hasher = Sha256::new();
    hasher.update(concat!("glint ", env!("CARGO_PKG_VERSION"), "\n"));
    let mut array = |name: &str, bytes: &[u8]| {
        // Name and length first, so bytes cannot shift from one array into the next.
        hasher.update(format!("{name} {}\n", bytes.len()));
        hasher.update(bytes);
    };
    // A perspective camera's parameters hash as they did before `projection` (and its padding)
    // joined them, so the settings, and the headers of files rendered with them, stay what they
    // were; an orthographic camera's hash them all, `projection` = 1 included.
    // The fields after `sampler` (the integrator's, hashed below) replaced 8 bytes of zero
    // padding, which hash as they did.
    let params_bytes = bytemuck::bytes_of(&params);
    let mut params_bytes = if params.projection == PROJECTION_PERSPECTIVE {
        params_bytes[..std::mem::offset_of!(Params, projection)].to_vec()
    } else {
        params_bytes[..std::mem::offset_of!(Params, integrator)].to_vec()
    };
    if params.projection != PROJECTION_PERSPECTIVE {
        params_bytes.extend_from_slice(&[0; 8]);
    }
    array("params", &params_bytes);
    // The sampler only where it is not the independent one, so earlier hashes stay as they
    // were (a perspective camera's bytes above stop before it).
    if params.sampler != 0 {
        array("sampler", bytemuck::bytes_of(&params.sampler));
    }
    // Likewise the integrator, and the splat film's scale that comes with bidirectional.
    if params.integrator != 0 {
        array("integrator", bytemuck::bytes_of(&params.integrator));
        array("splat_scale", bytemuck::bytes_of(&params.splat_scale));
    }
    // And the media, where there are any.
    if params.medium_count != 0 {
        let start = std::mem::offset_of!(Params, medium_count);
        let end = std::mem::offset_of!(Params, light_tree_nodes);
        array("media", &bytemuck::bytes_of(&params)[start..end]);
    }
    array("spheres", bytemuck::cast_slice(spheres));
    array("quads", bytemuck::cast_slice(quads));
    array("materials", bytemuck::cast_slice(materials));
    array("emitters", bytemuck::cast_slice(emitters));
    array("triangles", bytemuck::cast_slice(triangles));
    array("triangle normals", bytemuck::cast_slice(triangle_normals));
    array("textures", bytemuck::cast_slice(textures));
    array("texels", bytemuck::cast_slice(texels));
    array("triangle uvs", bytemuck::cast_slice(triangle_uvs));
    array("triangle uvs 1", bytemuck::cast_slice(triangle_uvs1));
    array("triangle tangents", bytemuck::cast_slice(triangle_tangents));
    array("triangle colors", bytemuck::cast_slice(triangle_colors));
    array(
        "environment texels",
        bytemuck::cast_slice(environment_texels),
    );
    array("environment alias", bytemuck::cast_slice(environment_alias));
    array("lights", bytemuck::cast_slice(lights));
    // Only where there are instances, so the hashes of scenes without them stay as they were;
    // without the BVH's node index, which is the BVH's as above.
    if !instances.is_empty() {
        let placed: Vec<_> = instances
            .iter()
            .map(|i| crate::kernel::types::Instance { blas_root: 0, ..*i })
            .collect();
        array("instances", bytemuck::cast_slice(&placed));
    }
    // Grid media's grids, where there are any.
    if !grids.is_empty() {
        array("grids", bytemuck::cast_slice(grids));
        array("grid voxels", bytemuck::cast_slice(grid_voxels));
    }
    // The light tree, where next-event estimation picks with one.
    if !light_tree_nodes.is_empty() {
        array(
            "light tree probability",
            bytemuck::bytes_of(&params.light_tree_probability),
        );
        array("light tree", bytemuck::cast_slice(light_tree_nodes));
        array("light tree trails", bytemuck::cast_slice(light_tree_trails));
    }
    let mut hex = String::with_capacity(64);
    for byte in hasher.finalize() {
        write!(hex, "{byte:02x}").expect("writing to a String");
    }
    hex
}

/// `0..16,32..64` (the ranges' text in the header and in messages).
pub fn format_ranges(ranges: &[Range<u32>]) -> String {
    let parts: Vec<String> = ranges.iter().map(format_range).collect();
    parts.join(",")
}

pub fn format_range(r: &Range<u32>) -> String {
    format!("{}..{}", r.start, r.end)
}

/// `A..B` with A < B.
pub fn parse_range(s: &str) -> Result<Range<u32>, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("expected A..B, got {s:?}"))?;
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("{t:?} in {s:?} is not a sample index"))
    };
    let (a, b) = (parse(a)?, parse(b)?);
    if a >= b {
        return Err(format!("the range {s:?} is empty: A must be < B"));
    }
    Ok(a..b)
}

fn parse_ranges(s: &str) -> Result<Vec<Range<u32>>, String> {
    let ranges = s
        .split(',')
        .map(parse_range)
        .collect::<Result<Vec<_>, _>>()?;
    if ranges.windows(2).any(|w| w[0].end > w[1].start) {
        return Err(format!("the ranges {s:?} are not sorted and disjoint"));
    }
    Ok(ranges)
}

impl Partial {
    /// Writes the file atomically (a temporary file in the same folder, then a rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        let a = &self.accumulation;
        let channel = |name: &str, values: &[[f32; 3]], c: usize| {
            AnyChannel::new(
                name,
                FlatSamples::F32(values.iter().map(|p| p[c]).collect()),
            )
        };
        let mut channels = SmallVec::new();
        let image = a.mean_image();
        for c in 0..3 {
            channels.push(channel(MEAN_CHANNELS[c], &image.pixels, c));
            channels.push(channel(M2_CHANNELS[c], &a.m2, c));
            if !a.splats.is_empty() {
                channels.push(channel(CAMERA_CHANNELS[c], &a.mean, c));
                for (w, name) in SPLAT_CHANNELS[c].iter().enumerate() {
                    let shift = if w == 0 { 32 } else { 0 };
                    let words = (0..a.mean.len())
                        .map(|i| (a.splats[3 * i + c] >> shift) as u32)
                        .collect();
                    channels.push(AnyChannel::new(*name, FlatSamples::U32(words)));
                }
            }
        }
        let format = if a.is_uniform() {
            FORMAT
        } else {
            channels.push(AnyChannel::new(
                COUNT_CHANNEL,
                FlatSamples::U32(a.counts.clone()),
            ));
            FORMAT_COUNTS
        };
        let info = &self.info;
        let mut attributes = LayerAttributes::default();
        // UTF-8 bytes as they are: exr's Text::from panics beyond Latin-1 (a path may hold any).
        let text = |s: &str| {
            AttributeValue::Text(Text::from_bytes_unchecked(SmallVec::from_slice(
                s.as_bytes(),
            )))
        };
        let adaptive = info.adaptive.map(|a| ("glint.adaptive", a.to_header()));
        for (key, value) in [
            ("glint.format", format.to_string()),
            ("glint.samples", format_ranges(&info.ranges)),
            ("glint.target", format_range(&info.target)),
            ("glint.spp", info.spp.to_string()),
            ("glint.seed", info.seed.to_string()),
            ("glint.settings", info.settings.clone()),
            ("glint.scene", info.scene.clone()),
            ("glint.device", info.device.clone()),
        ]
        .into_iter()
        .chain(adaptive)
        {
            attributes.other.insert(Text::from(key), text(&value));
        }
        if !a.splats.is_empty() {
            // The exact f32, as its bits.
            let scale = format!("{:08x}", a.splat_scale.to_bits());
            attributes
                .other
                .insert(Text::from("glint.splat_scale"), text(&scale));
            attributes
                .other
                .insert(Text::from("glint.batches"), text(&a.batches.to_string()));
        }
        let layer = Layer::new(
            (a.width as usize, a.height as usize),
            attributes,
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(channels),
        );
        let image = exr::prelude::Image::from_layer(layer);
        let mut bytes = Vec::new();
        image
            .write()
            .to_buffered(std::io::Cursor::new(&mut bytes))
            .with_context(|| format!("cannot encode {}", path.display()))?;
        crate::exr_header::sort_attributes(&mut bytes)
            .map_err(|e| anyhow::anyhow!("cannot encode {}: {e}", path.display()))?;
        // Through a temporary file next to `path`, then a rename (src/image/atomic_write.rs): a
        // reader never sees half a file, and nothing is left on an error.
        crate::image::atomic_write::write_atomically(path, |w| std::io::Write::write_all(w, &bytes))
    }

    /// Reads a partial file. Every problem (not an EXR, truncated, a missing channel or
    /// attribute, a size beyond the limits, a non-finite value) is an error naming the file.
    pub fn read(path: &Path) -> Result<Partial, String> {
        let fail = |what: String| format!("{}: {what}", path.display());
        // The header alone first: its size decides how much the full read allocates.
        let meta = exr::meta::MetaData::read_from_file(path, true)
            .map_err(|e| fail(format!("not a readable EXR file ({e})")))?;
        let header = meta
            .headers
            .first()
            .ok_or_else(|| fail("the EXR file has no layer".into()))?;
        let (width, height) = (header.layer_size.0, header.layer_size.1);
        if width == 0
            || height == 0
            || width > MAX_IMAGE_SIDE as usize
            || height > MAX_IMAGE_SIDE as usize
            || width * height > MAX_IMAGE_PIXELS as usize
        {
            return Err(fail(format!(
                "a {width}×{height} image is beyond glint's limits"
            )));
        }
        let attributes = &header.own_attributes.other;
        let format = text_attribute(attributes, "glint.format").ok_or_else(|| {
            fail("not a glint partial render (no glint.format attribute; only EXR files written by glint render can be merged or resumed)".into())
        })?;
        if format != FORMAT && format != FORMAT_COUNTS {
            return Err(fail(format!(
                "glint.format is {format:?}; this glint reads {FORMAT:?} and {FORMAT_COUNTS:?}"
            )));
        }
        let get = |key: &str| {
            text_attribute(attributes, key)
                .ok_or_else(|| fail(format!("the header has no {key} attribute")))
        };
        let number = |key: &str| -> Result<u32, String> {
            let value = get(key)?;
            value
                .parse()
                .map_err(|_| fail(format!("{key} is {value:?}, not a whole number")))
        };
        let ranges = parse_ranges(&get("glint.samples")?)
            .map_err(|e| fail(format!("glint.samples: {e}")))?;
        let target =
            parse_range(&get("glint.target")?).map_err(|e| fail(format!("glint.target: {e}")))?;
        let info = PartialInfo {
            ranges,
            target,
            spp: number("glint.spp")?,
            seed: number("glint.seed")?,
            settings: get("glint.settings")?,
            scene: get("glint.scene")?,
            device: get("glint.device")?,
            adaptive: match text_attribute(attributes, "glint.adaptive") {
                Some(text) => Some(
                    Adaptive::from_header(&text)
                        .map_err(|e| fail(format!("glint.adaptive: {e}")))?,
                ),
                None => None,
            },
        };
        let last = info
            .ranges
            .last()
            .expect("parse_ranges returns at least one")
            .end;
        if last > info.spp || info.target.end > info.spp {
            return Err(fail(format!(
                "the samples {} lie beyond the render's {} spp",
                format_ranges(&info.ranges),
                info.spp
            )));
        }
        let count = u32::try_from(info.count()).map_err(|_| fail("too many samples".into()))?;

        let image = exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .pedantic()
            .from_file(path)
            .map_err(|e| fail(format!("cannot read the pixels ({e})")))?;
        let layer = &image.layer_data;
        let pixels = width * height;
        let channel = |name: &str| -> Result<&[f32], String> {
            let found = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name == *name)
                .ok_or_else(|| fail(format!("the channel {name} is missing")))?;
            match &found.sample_data {
                FlatSamples::F32(v) if v.len() == pixels => Ok(v),
                FlatSamples::F32(_) => {
                    Err(fail(format!("the channel {name} has the wrong length")))
                }
                _ => Err(fail(format!("the channel {name} is not 32-bit float"))),
            }
        };
        let gather = |names: [&str; 3]| -> Result<Vec<[f32; 3]>, String> {
            let [r, g, b] = [channel(names[0])?, channel(names[1])?, channel(names[2])?];
            let mut out = Vec::with_capacity(pixels);
            for i in 0..pixels {
                let p = [r[i], g[i], b[i]];
                if let Some(c) = p.iter().position(|v| !v.is_finite()) {
                    return Err(fail(format!(
                        "pixel ({}, {}) has a non-finite {}",
                        i % width,
                        i / width,
                        names[c]
                    )));
                }
                out.push(p);
            }
            Ok(out)
        };
        let has_splats = layer
            .channel_data
            .list
            .iter()
            .any(|c| c.name == *CAMERA_CHANNELS[0]);
        let mut splats = Vec::new();
        let mut splat_scale = 0.0;
        let mut batches = 0;
        if has_splats {
            let word = |name: &str| -> Result<&[u32], String> {
                let found = layer
                    .channel_data
                    .list
                    .iter()
                    .find(|c| c.name == *name)
                    .ok_or_else(|| fail(format!("the channel {name} is missing")))?;
                match &found.sample_data {
                    FlatSamples::U32(v) if v.len() == pixels => Ok(v),
                    _ => Err(fail(format!(
                        "the channel {name} is not 32-bit unsigned of the image's size"
                    ))),
                }
            };
            splats = vec![0u64; 3 * pixels];
            for (c, [high, low]) in SPLAT_CHANNELS.iter().enumerate() {
                let (high, low) = (word(high)?, word(low)?);
                for i in 0..pixels {
                    splats[3 * i + c] = ((high[i] as u64) << 32) | low[i] as u64;
                }
            }
            let bits = text_attribute(&layer.attributes.other, "glint.splat_scale")
                .and_then(|s| u32::from_str_radix(&s, 16).ok())
                .ok_or_else(|| {
                    fail("the attribute glint.splat_scale is missing or not hex".into())
                })?;
            splat_scale = f32::from_bits(bits);
            if !(splat_scale.is_finite() && splat_scale > 0.0) {
                return Err(fail(
                    "the attribute glint.splat_scale is not a positive number".into(),
                ));
            }
            // The M2 channels are the sum of squares between this many batch means.
            batches = text_attribute(&layer.attributes.other, "glint.batches")
                .and_then(|s| s.parse::<u32>().ok())
                .ok_or_else(|| {
                    fail("the attribute glint.batches is missing or not a whole number (a bidirectional render from a glint before its variance came from batch means: render it again)".into())
                })?;
            if (count > 0 && batches == 0) || batches > count {
                return Err(fail(format!(
                    "glint.batches is {batches}, impossible for {count} samples per pixel"
                )));
            }
        }
        let counts = if format == FORMAT_COUNTS {
            let found = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name == *COUNT_CHANNEL)
                .ok_or_else(|| fail(format!("the channel {COUNT_CHANNEL} is missing")))?;
            let counts = match &found.sample_data {
                FlatSamples::U32(v) if v.len() == pixels => v.clone(),
                _ => {
                    return Err(fail(format!(
                        "the channel {COUNT_CHANNEL} is not one 32-bit unsigned count per pixel"
                    )))
                }
            };
            if let Some(i) = counts.iter().position(|&n| n > count) {
                return Err(fail(format!(
                    "pixel ({}, {}) holds {} samples, more than the file's {count}",
                    i % width,
                    i / width,
                    counts[i]
                )));
            }
            counts
        } else {
            vec![count; pixels]
        };
        let accumulation = Accumulation {
            width: width as u32,
            height: height as u32,
            count,
            counts,
            mean: gather(if has_splats {
                CAMERA_CHANNELS
            } else {
                MEAN_CHANNELS
            })?,
            m2: gather(M2_CHANNELS)?,
            splats,
            splat_scale,
            batches,
        };
        Ok(Partial { info, accumulation })
    }
}

fn text_attribute(attributes: &HashMap<Text, AttributeValue>, key: &str) -> Option<String> {
    match attributes.get(&Text::from(key))? {
        AttributeValue::Text(t) => Some(String::from_utf8_lossy(t.as_slice()).into_owned()),
        _ => None,
    }
}

/// Writes a render's image to `path`: a partial file (mean, M2 and header) for `.exr`, so it
/// can be resumed or merged, and the mean in the file's own format otherwise (`.png`).
pub fn write_image(path: &Path, partial: &Partial) -> Result<()> {
    match crate::image::format::ImageFormat::from_path(path).map_err(anyhow::Error::msg)? {
        crate::image::format::ImageFormat::Exr => partial.write(path),
        _ => partial.accumulation.mean_image().write(path),
    }
}
