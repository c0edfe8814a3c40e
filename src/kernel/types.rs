//! The structs the kernel reads, byte for byte (WGSL side: `shaders/core/types.wgsl`).
//! The CPU reference traces from these same structs, so both devices see identical numbers.
//! `tests/suite/layout.rs` checks every offset and size against the WGSL with naga's layouter.

use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub eye: [f32; 3],
    pub width: u32,
    /// Unit vector from the eye towards the target.
    pub forward: [f32; 3],
    pub height: u32,
    /// Image-right and image-up, scaled to half the viewport at unit distance (perspective) or
    /// to half the view's width and height in world units (orthographic).
    pub right: [f32; 3],
    pub sample_start: u32,
    pub up: [f32; 3],
    pub sample_count: u32,
    pub background: [f32; 3],
    pub max_bounces: u32,
    /// Thin lens: unit image-right and image-up times the lens radius (zero for a pinhole).
    pub lens_right: [f32; 3],
    /// Distance from the eye to the plane in focus, along `forward`.
    pub focus_distance: f32,
    pub lens_up: [f32; 3],
    /// 1: next-event estimation with multiple importance sampling; 0: BSDF sampling only.
    pub light_sampling: u32,
    pub seed: u32,
    pub sphere_count: u32,
    pub quad_count: u32,
    pub material_count: u32,
    pub emitter_count: u32,
    /// Russian roulette after the scattering at this bounce and later ones (`ROULETTE_OFF`: off).
    pub roulette_start: u32,
    /// Samples already in the accumulators (the pairwise merge's n_old): `sample_start` less
    /// the first sample of a partial render (`--samples A..B`), which need not start at 0.
    pub accumulated_samples: u32,
    /// 1: accumulate the denoiser's albedo, normal and depth; needs `KernelFeatures::aovs`.
    pub aovs: u32,
    /// Firefly clamp: the most a contribution of scattered light may add (0: off).
    pub radiance_clamp: f32,
    /// Meshes (issue 11).
    pub triangle_count: u32,
    /// The environment map's size in texels (0 × 0: none; `background` lights the scene).
    pub environment_width: u32,
    pub environment_height: u32,
    /// cos and sin of the map's rotation about +y (`src/scene/environment.rs`).
    pub environment_cos: f32,
    pub environment_sin: f32,
    /// Probability that light sampling picks the environment map (0 when it is not sampled).
    pub environment_light_probability: f32,
    /// Point, spot and directional lights (`lights`).
    pub light_count: u32,
    /// `PROJECTION_PERSPECTIVE` or `PROJECTION_ORTHOGRAPHIC` (`src/cpu/core/camera.rs`).
    pub projection: u32,
    /// `SAMPLER_INDEPENDENT` or `SAMPLER_SOBOL` (`src/cpu/core/rng.rs`).
    pub sampler: u32,
    /// `INTEGRATOR_PATH` or `INTEGRATOR_BDPT` (`src/cpu/integrator/`).
    pub integrator: u32,
    /// Fixed-point scale of the splat film (`src/cpu/integrator/splat.rs`).
    pub splat_scale: f32,
    /// A sphere around every surface and light: where the light paths of the environment map
    /// and the suns start (a disk of this radius facing the light, `src/cpu/lights/emission.rs`).
    pub scene_center: [f32; 3],
    pub scene_radius: f32,
    /// Participating media (`src/cpu/media/`): how many of `media` are used (0: none, and the
    /// kernel compiles media out), the slot of the medium filling the scene and the slot the
    /// camera starts in besides it, each [`NO_MEDIUM`] where there is none.
    pub medium_count: u32,
    pub global_medium: u32,
    pub camera_medium: u32,
    pub _pad: u32,
    pub media: [Medium; MAX_MEDIUM_SLOTS],
    /// Nodes of the light tree next-event estimation picks finite emitters with
    /// (`KernelScene::light_tree_nodes`, `src/cpu/lights/light_tree.rs`); 0: none, the alias
    /// table by power picks them.
    pub light_tree_nodes: u32,
    /// The probability that light sampling picks a finite emitter (one in the tree) rather
    /// than the environment map or a sun, which keep their own probabilities.
    pub light_tree_probability: f32,
    pub _pad_tree: [u32; 2],
}

/// The media's slots in `Params` (`crate::scene::medium::MAX_MEDIUM_SLOTS`).
pub const MAX_MEDIUM_SLOTS: usize = crate::scene::medium::MAX_MEDIUM_SLOTS;

/// `Params::global_medium` and `camera_medium`, and `Medium::boundary`: none.
pub const NO_MEDIUM: u32 = u32::MAX;

/// A homogeneous medium as the kernel reads it (`src/cpu/media/medium.rs`): extinction and
/// scattering per unit length, Henyey–Greenstein's g, and the material whose objects bound it
/// (their inside is this medium), or [`NO_MEDIUM`] for the global medium and a camera's.
/// For a grid medium, `grid` indexes `KernelScene::grids` and the coefficients are per unit
/// density; [`NO_GRID`] for a homogeneous one.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Medium {
    pub sigma_t: [f32; 3],
    pub g: f32,
    pub sigma_s: [f32; 3],
    pub boundary: u32,
    pub grid: u32,
    pub _pad: [u32; 3],
}

/// `Medium::grid`: a homogeneous medium.
pub const NO_GRID: u32 = u32::MAX;

/// A heterogeneous medium's density grid as the kernel reads it (`src/cpu/media/grid.rs`):
/// the map from the scene to continuous grid coordinates (voxel i's centre at i + ½, the grid
/// covering [0, dims]), as the rows of a 3 × 4 matrix; the dense densities, x fastest, from
/// `voxels` in `KernelScene::grid_voxels`; and the majorants of blocks of `block` voxels a
/// side, `blocks` of them along each axis, from `majorants` in the same array.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GridMedium {
    pub to_grid_x: [f32; 4],
    pub to_grid_y: [f32; 4],
    pub to_grid_z: [f32; 4],
    pub dims: [u32; 3],
    pub voxels: u32,
    pub blocks: [u32; 3],
    pub majorants: u32,
    pub block: u32,
    pub _pad: [u32; 3],
}

/// `Params::integrator`: unidirectional path tracing with next-event estimation.
pub const INTEGRATOR_PATH: u32 = 0;
/// `Params::integrator`: bidirectional path tracing (`src/cpu/integrator/bdpt/`).
pub const INTEGRATOR_BDPT: u32 = 1;

/// `Params::roulette_start` that turns Russian roulette off.
pub const ROULETTE_OFF: u32 = u32::MAX;

/// `Params::projection`: camera rays from the eye (or the lens) through the image plane.
pub const PROJECTION_PERSPECTIVE: u32 = 0;
/// `Params::projection`: parallel camera rays along `forward`, from the image plane through
/// the eye.
pub const PROJECTION_ORTHOGRAPHIC: u32 = 1;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Sphere {
    pub center: [f32; 3],
    pub radius: f32,
    pub material: u32,
    /// Probability that light sampling picks this sphere (0 when it does not emit).
    pub light_probability: f32,
    pub _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Quad {
    pub corner: [f32; 3],
    pub material: u32,
    pub edge_u: [f32; 3],
    pub area: f32,
    pub edge_v: [f32; 3],
    /// The plane is `dot(normal, p) == plane_offset`.
    pub plane_offset: f32,
    pub normal: [f32; 3],
    /// Probability that light sampling picks this quad (0 when it does not emit).
    pub light_probability: f32,
    /// `edge_u / dot(edge_u, edge_u)`.
    pub u_dual: [f32; 3],
    pub pad1: f32,
    /// `edge_v / dot(edge_v, edge_v)`.
    pub v_dual: [f32; 3],
    pub pad2: f32,
}

pub const MATERIAL_DIFFUSE: u32 = 0;
pub const MATERIAL_SPECULAR: u32 = 1;
pub const MATERIAL_METAL: u32 = 2;
pub const MATERIAL_DIELECTRIC: u32 = 3;
/// glTF's metallic-roughness material (`src/cpu/materials/pbr.rs`).
pub const MATERIAL_PBR: u32 = 4;
/// KHR_materials_unlit: reflects nothing, emits its emission (the base colour) times the
/// vertex colour (`src/cpu/textures/vertex_color.rs`).
pub const MATERIAL_UNLIT: u32 = 5;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Material {
    /// Diffuse albedo, mirror reflectance, metal F0, or glass transmission tint.
    pub albedo: [f32; 3],
    pub kind: u32,
    /// `emission * strength`.
    pub emission: [f32; 3],
    /// GGX alpha (roughness squared) for metal.
    pub alpha: f32,
    pub ior: f32,
    /// Index into the texture descriptors multiplying `albedo` at the hit, or [`NO_TEXTURE`].
    pub color_texture: u32,
    /// Texture whose x multiplies the roughness (alpha by x²) and y `metallic`, or [`NO_TEXTURE`].
    pub roughness_texture: u32,
    /// PBR: the conductor's share.
    pub metallic: f32,
    /// PBR: KHR_materials_specular's colour and factor for the dielectric layer.
    pub specular_color: [f32; 3],
    pub specular: f32,
    /// Texture multiplying `emission` at the hit (glTF's emissiveTexture), or [`NO_TEXTURE`].
    pub emission_texture: u32,
    /// Tangent-space normal map (glTF's normalTexture), or [`NO_TEXTURE`]; its x and y are
    /// scaled by `normal_scale` (`src/cpu/textures/normal_map.rs`).
    pub normal_texture: u32,
    pub normal_scale: f32,
    /// glTF's alphaMode: [`ALPHA_OPAQUE`], [`ALPHA_MASK`] or [`ALPHA_BLEND`].
    pub alpha_mode: u32,
    /// The base colour's alpha (glTF's baseColorFactor.a); the colour texture's alpha
    /// multiplies it. Read only where `alpha_mode` is not opaque.
    pub opacity: f32,
    /// MASK: a hit whose alpha is below this is no hit.
    pub alpha_cutoff: f32,
    /// PBR: the share of the dielectric base that transmits (KHR_materials_transmission).
    pub transmission: f32,
    /// Texture whose x (glTF's R channel) multiplies `transmission`, or [`NO_TEXTURE`].
    pub transmission_texture: u32,
    /// PBR with transmission: the colour that white light has after `attenuation_distance`
    /// inside the mesh (KHR_materials_volume, Beer–Lambert).
    pub attenuation_color: [f32; 3],
    /// 0 where there is no attenuation (glTF's default, +∞).
    pub attenuation_distance: f32,
    /// PBR: KHR_materials_clearcoat's layer (`src/cpu/materials/clearcoat.rs`): its weight, its GGX α
    /// (clearcoat roughness squared), and textures whose x (glTF's R) multiplies the weight
    /// and whose y (G) multiplies the roughness (α by y²), or [`NO_TEXTURE`].
    pub clearcoat: f32,
    pub clearcoat_alpha: f32,
    pub clearcoat_texture: u32,
    pub clearcoat_roughness_texture: u32,
    /// The coat's own tangent-space normal map and its scale, or [`NO_TEXTURE`].
    pub clearcoat_normal_texture: u32,
    pub clearcoat_normal_scale: f32,
    /// PBR: KHR_materials_sheen (`src/cpu/materials/sheen.rs`): the sheen roughness (not squared), and
    /// textures multiplying the colour (RGB) and the roughness (its alpha), or [`NO_TEXTURE`].
    pub sheen_roughness: f32,
    pub sheen_color_texture: u32,
    /// Black where there is no sheen.
    pub sheen_color: [f32; 3],
    pub sheen_roughness_texture: u32,
}

/// `Material::alpha_mode`: glTF's OPAQUE (alpha ignored), MASK (cut at `alpha_cutoff`) and
/// BLEND (stochastic transparency).
pub const ALPHA_OPAQUE: u32 = 0;
pub const ALPHA_MASK: u32 = 1;
pub const ALPHA_BLEND: u32 = 2;

/// `Material::color_texture` and `roughness_texture` when the value is constant.
pub const NO_TEXTURE: u32 = u32::MAX;

pub const PRIMITIVE_SPHERE: u32 = 0;
pub const PRIMITIVE_QUAD: u32 = 1;

/// One entry per emitting primitive, and one slot of Vose's alias table over them, for
/// choosing an emitter in proportion to its power in O(1): slot k keeps its own emitter with
/// probability `alias_threshold`, else takes the one copied into `alias_*` (copied, not
/// referred to by index, so a pick reads one entry).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Emitter {
    pub primitive: u32,
    pub index: u32,
    /// The probability that light sampling picks this emitter.
    pub probability: f32,
    pub alias_threshold: f32,
    pub alias_primitive: u32,
    pub alias_index: u32,
    pub alias_probability: f32,
    pub _pad: u32,
}

pub const PRIMITIVE_TRIANGLE: u32 = 2;

/// A node of the light tree (Conty Estevez and Kulla 2018, pbrt-v4's `LightBounds`): the box
/// around its emitters, their summed power `phi`, and the cone bounding their normals (axis,
/// cos θo) and how far from a normal they emit (cos θe); `two_sided` (0 or 1) where any of them
/// emits from both sides. An interior node's first child follows it and `child` is its second;
/// a leaf has `child` 0 and holds one emitter (`primitive`, `index`, as in `Emitter`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightTreeNode {
    pub lo: [f32; 3],
    pub phi: f32,
    pub hi: [f32; 3],
    pub cos_theta_o: f32,
    pub axis: [f32; 3],
    pub cos_theta_e: f32,
    pub child: u32,
    pub primitive: u32,
    pub index: u32,
    pub two_sided: u32,
}

/// A mesh triangle: what intersection and light sampling read (48 bytes, so a BVH leaf's
/// triangles stay compact). Its unit normal is `normalize((v1 − v0) × (v2 − v0))`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Triangle {
    pub v0: [f32; 3],
    pub material: u32,
    pub v1: [f32; 3],
    /// Probability that light sampling picks this triangle (0 when it does not emit).
    pub light_probability: f32,
    pub v2: [f32; 3],
    pub area: f32,
}

/// A triangle's vertex normals, read only at the closest hit, for shading.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TriangleNormals {
    pub n0: [f32; 3],
    /// 1: interpolate the vertex normals; 0: flat (the geometric normal shades).
    pub smooth_shading: u32,
    pub n1: [f32; 3],
    pub _pad1: u32,
    pub n2: [f32; 3],
    pub _pad2: u32,
}

/// A triangle's vertex tangents for normal mapping (glTF's TANGENT, or MikkTSpace's): xyz the
/// unit tangent along increasing u, w the bitangent's sign (bitangent = w · normal × tangent,
/// along increasing v, glint's v being up). One per triangle when a material has a normal map.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TriangleTangents {
    pub t0: [f32; 4],
    pub t1: [f32; 4],
    pub t2: [f32; 4],
}

/// A node of the flattened BVH. An inner node (`count == 0`) has its children at `first` and
/// `first + 1`; a leaf holds `bvh_primitives[first .. first + count]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

/// A node of the 4-wide BVH (`src/kernel/bvh/wide.rs`): its up to four children's boxes, one
/// axis bound per vector (the box test runs on all four at once), and what each child is: an
/// inner node at `bvh_wide_nodes[first]` (`count == 0`), a leaf holding
/// `bvh_primitives[first .. first + count]`, or no child (`count == WIDE_EMPTY_CHILD`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhWideNode {
    pub min_x: [f32; 4],
    pub min_y: [f32; 4],
    pub min_z: [f32; 4],
    pub max_x: [f32; 4],
    pub max_y: [f32; 4],
    pub max_z: [f32; 4],
    pub first: [u32; 4],
    pub count: [u32; 4],
}

/// A [`BvhWideNode`]'s `count` for a slot that holds no child.
pub const WIDE_EMPTY_CHILD: u32 = u32::MAX;

/// A BVH leaf's primitive reference: the kind in the top two bits, the index below.
pub const PRIMITIVE_KIND_SHIFT: u32 = 30;
pub const PRIMITIVE_INDEX_MASK: u32 = (1 << PRIMITIVE_KIND_SHIFT) - 1;

/// A top-level BVH reference's kind for an instance (`Instance`): the one kind a leaf holds
/// that is not a light's, so it may share the value 3 with [`PRIMITIVE_ENVIRONMENT`], which
/// names a light and never appears in a leaf.
pub const PRIMITIVE_INSTANCE: u32 = 3;

/// `ClosestPrimitive::instance` of a hit on a primitive placed as it is (not through an
/// instance): its arrays hold it in the scene's coordinates.
pub const NO_INSTANCE: u32 = u32::MAX;

/// A placement of an instanced mesh (`src/kernel/scene/acceleration.rs` lays them out, `shaders/geometry/instance.wgsl`
/// reads them): its transforms as the rows of 3×4 matrices (a point p goes to
/// `(row · (p, 1))` per row), and its mesh's bottom-level BVH, whose root is
/// `bvh_nodes[blas_root]` and whose leaves reference the mesh's triangles, stored once in the
/// mesh's own coordinates at `triangles[first_triangle ..][.. triangle_count]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Instance {
    pub to_world: [[f32; 4]; 3],
    pub to_object: [[f32; 4]; 3],
    pub blas_root: u32,
    pub first_triangle: u32,
    pub triangle_count: u32,
    pub _pad: u32,
}

pub const TEXTURE_IMAGE: u32 = 0;
pub const TEXTURE_CHECKER: u32 = 1;

/// A texture (`src/scene/texture.rs` builds them, `shaders/textures/texture.wgsl` reads them): an image
/// whose texels are `texels[first_texel ..][.. width * height]`, bottom row first, or a checker
/// of two colours with `scale` squares per unit of u and of v.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Texture {
    /// `TEXTURE_IMAGE` or `TEXTURE_CHECKER`.
    pub kind: u32,
    pub first_texel: u32,
    pub width: u32,
    pub height: u32,
    /// The checker's colour where ⌊u·scale⌋ + ⌊v·scale⌋ is even (the square at the origin).
    pub color0: [f32; 3],
    pub scale: f32,
    pub color1: [f32; 3],
    /// Image lookups: `TEXTURE_WRAP_*` for u in bits 0–7 and for v in bits 8–15, and
    /// [`TEXTURE_NEAREST`] for unfiltered lookups.
    pub sampling: u32,
    /// The texture coordinates the lookup uses: (u', v') = (transform_u · (u, v, 1),
    /// transform_v · (u, v, 1)) (glTF's KHR_texture_transform; the identity otherwise).
    pub transform_u: [f32; 3],
    /// The texture coordinate set the lookup reads: 0, or 1 (glTF's TEXCOORD_1).
    pub uv_set: u32,
    pub transform_v: [f32; 3],
    pub _pad1: u32,
}

/// [`Texture::sampling`]'s wrap modes (glTF's sampler modes) and its unfiltered flag.
pub const TEXTURE_WRAP_REPEAT: u32 = 0;
pub const TEXTURE_WRAP_CLAMP: u32 = 1;
pub const TEXTURE_WRAP_MIRROR: u32 = 2;
pub const TEXTURE_NEAREST: u32 = 1 << 16;

impl Default for Texture {
    fn default() -> Self {
        Texture {
            kind: TEXTURE_IMAGE,
            first_texel: 0,
            width: 0,
            height: 0,
            color0: [0.0; 3],
            scale: 0.0,
            color1: [0.0; 3],
            sampling: 0,
            transform_u: [1.0, 0.0, 0.0],
            uv_set: 0,
            transform_v: [0.0, 1.0, 0.0],
            _pad1: 0,
        }
    }
}

/// A triangle's texture coordinates at its three vertices (zero where the mesh has none).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TriangleUvs {
    pub uv0: [f32; 2],
    pub uv1: [f32; 2],
    pub uv2: [f32; 2],
}

/// A triangle's vertex colours (glTF's COLOR_0, linear RGBA; white where the mesh has none),
/// multiplying the base colour and its alpha. One per triangle when a mesh has them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TriangleColors {
    pub c0: [f32; 4],
    pub c1: [f32; 4],
    pub c2: [f32; 4],
}

/// The emitter table's entry for the environment map (`index` 0).
pub const PRIMITIVE_ENVIRONMENT: u32 = 3;

/// One texel of the environment map: its radiance, and the solid-angle density with which
/// environment sampling picks a direction in it (selection among emitters excluded).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EnvironmentTexel {
    pub radiance: [f32; 3],
    pub pdf: f32,
}

/// An entry of the alias table over the environment map's texels: texel k is kept with
/// probability `threshold`, else texel `alias` is taken.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EnvironmentAlias {
    pub threshold: f32,
    pub alias_texel: u32,
}

/// The emitter table's entry for a point, spot or directional light (`index` into the lights).
pub const PRIMITIVE_LIGHT: u32 = 4;

pub const LIGHT_POINT: u32 = 0;
pub const LIGHT_SPOT: u32 = 1;
/// A directional light: a delta sun when `sun_one_minus_cos` is 0, else a disk.
pub const LIGHT_SUN: u32 = 2;

/// A point, spot or directional light (`src/scene/light.rs` builds them,
/// `shaders/lights/punctual.wgsl` samples them).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Light {
    pub position: [f32; 3],
    /// `LIGHT_POINT`, `LIGHT_SPOT` or `LIGHT_SUN`.
    pub kind: u32,
    /// Unit: the way the light travels (a spot's axis, the sun's rays).
    pub direction: [f32; 3],
    /// Probability that light sampling picks this light.
    pub light_probability: f32,
    /// Point and spot: radiant intensity (W/sr); delta sun: irradiance (W/m²); sun disk: the
    /// disk's radiance. Per channel, colour included.
    pub emitted: [f32; 3],
    /// glTF's spot falloff clamp(cos · scale + offset, 0, 1)²; scale 0 and offset 1 (no
    /// falloff) for the others.
    pub spot_scale: f32,
    pub spot_offset: f32,
    /// 1 − cos of a sun disk's half angle (0: a delta sun).
    pub sun_one_minus_cos: f32,
    pub _pad: [u32; 2],
}
