// Data shared by every kernel stage. The Rust side is src/kernel/types.rs; the test
// tests/suite/layout.rs checks with naga's layouter that both agree field by field.

struct Params {
    eye: vec3<f32>,
    width: u32,
    // Unit vector from the eye towards the target.
    forward: vec3<f32>,
    height: u32,
    // Image-right and image-up, scaled to half the viewport at unit distance (perspective) or
    // to half the view's width and height in world units (orthographic).
    right: vec3<f32>,
    // The global index of this batch's first sample (the random streams depend on it).
    sample_start: u32,
    up: vec3<f32>,
    sample_count: u32,
    background: vec3<f32>,
    max_bounces: u32,
    // Thin lens: unit image-right and image-up times the lens radius (zero for a pinhole).
    lens_right: vec3<f32>,
    // Distance from the eye to the plane in focus, along `forward`.
    focus_distance: f32,
    lens_up: vec3<f32>,
    // 1: next-event estimation with multiple importance sampling; 0: BSDF sampling only.
    light_sampling: u32,
    seed: u32,
    sphere_count: u32,
    quad_count: u32,
    material_count: u32,
    emitter_count: u32,
    // Russian roulette after the scattering at this bounce and later ones (0xffffffff: off).
    roulette_start: u32,
    // Samples already in the accumulators (the pairwise merge's n_old): sample_start less
    // the first sample of a partial render (--samples A..B), which need not start at 0.
    accumulated_samples: u32,
    // 1: accumulate the denoiser's albedo, normal and depth (aov.wgsl); needs AOVS compiled in.
    aovs: u32,
    // Firefly clamp: the most a contribution of scattered light may add (0: off; path.wgsl).
    radiance_clamp: f32,
    // Meshes (issue 11).
    triangle_count: u32,
    // The environment map's size in texels (0 x 0: none; `background` lights the scene).
    environment_width: u32,
    environment_height: u32,
    // cos and sin of the map's rotation about +y (environment.wgsl).
    environment_cos: f32,
    environment_sin: f32,
    // Probability that light sampling picks the environment map (0 when it is not sampled).
    environment_light_probability: f32,
    light_count: u32,
    // PROJECTION_PERSPECTIVE or PROJECTION_ORTHOGRAPHIC (camera.wgsl).
    projection: u32,
    // SAMPLER_INDEPENDENT or SAMPLER_SOBOL (rng.wgsl).
    sampler: u32,
    // INTEGRATOR_PATH or INTEGRATOR_BDPT (integrator/).
    integrator: u32,
    // Fixed-point scale of the splat film (splat.wgsl).
    splat_scale: f32,
    // A sphere around every surface and light: where the light paths of the environment map
    // and the suns start (emission.wgsl).
    scene_center: vec3<f32>,
    scene_radius: f32,
    // Participating media (media/medium.wgsl): the slots of `media` in use (0: none), the
    // slot filling the scene and the one the camera starts in besides it (NO_MEDIUM: none).
    medium_count: u32,
    global_medium: u32,
    camera_medium: u32,
    media: array<Medium, 8>,
    // The light tree's nodes (0: none; the alias table picks every emitter) and the
    // probability of picking a finite emitter, one in the tree (lights/light_tree.wgsl).
    light_tree_nodes: u32,
    light_tree_probability: f32,
}

const NO_MEDIUM: u32 = 0xffffffffu;

// A homogeneous medium (src/kernel/types.rs): extinction and scattering per unit length,
// Henyey-Greenstein's g, and the material whose objects bound it, or NO_MEDIUM.
// A grid medium's coefficients are per unit density, and grid indexes grids (NO_GRID: a
// homogeneous medium).
struct Medium {
    sigma_t: vec3<f32>,
    g: f32,
    sigma_s: vec3<f32>,
    boundary: u32,
    grid: u32,
}

const NO_GRID: u32 = 0xffffffffu;

// A density grid (src/kernel/types.rs): scene to grid coordinates (rows of a 3 x 4 matrix),
// the dense densities from `voxels` in grid_voxels, the blocks' majorants from `majorants`.
struct GridMedium {
    to_grid_x: vec4<f32>,
    to_grid_y: vec4<f32>,
    to_grid_z: vec4<f32>,
    dims: vec3<u32>,
    voxels: u32,
    blocks: vec3<u32>,
    majorants: u32,
    block: u32,
}

const INTEGRATOR_PATH: u32 = 0u;
const INTEGRATOR_BDPT: u32 = 1u;

// Params.projection: camera rays from the eye (or the lens) through the image plane, or
// parallel ones along `forward` from the image plane through the eye.
const PROJECTION_PERSPECTIVE: u32 = 0u;
const PROJECTION_ORTHOGRAPHIC: u32 = 1u;

struct Sphere {
    center: vec3<f32>,
    radius: f32,
    material: u32,
    // Probability that light sampling picks this sphere (0 when it does not emit).
    light_probability: f32,
}

struct Quad {
    corner: vec3<f32>,
    material: u32,
    edge_u: vec3<f32>,
    area: f32,
    edge_v: vec3<f32>,
    // The plane is dot(normal, p) == plane_offset.
    plane_offset: f32,
    normal: vec3<f32>,
    // Probability that light sampling picks this quad (0 when it does not emit).
    light_probability: f32,
    // edge_u / dot(edge_u, edge_u): dot(u_dual, p - corner) is the position along edge_u in [0, 1].
    u_dual: vec3<f32>,
    pad1: f32,
    v_dual: vec3<f32>,
    pad2: f32,
}

const MATERIAL_DIFFUSE: u32 = 0u;
const MATERIAL_SPECULAR: u32 = 1u;
const MATERIAL_METAL: u32 = 2u;
const MATERIAL_DIELECTRIC: u32 = 3u;
const MATERIAL_PBR: u32 = 4u;
// KHR_materials_unlit: reflects nothing, emits its emission (the base colour) times the vertex
// colour (vertex_color.wgsl).
const MATERIAL_UNLIT: u32 = 5u;

// Material.alpha_mode: glTF's OPAQUE, MASK and BLEND.
const ALPHA_OPAQUE: u32 = 0u;
const ALPHA_MASK: u32 = 1u;
const ALPHA_BLEND: u32 = 2u;

struct Material {
    // Diffuse albedo, mirror reflectance, metal F0, or glass transmission tint.
    albedo: vec3<f32>,
    kind: u32,
    // emission * strength, already multiplied on the host.
    emission: vec3<f32>,
    // GGX alpha (roughness squared) for metal.
    alpha: f32,
    ior: f32,
    // Texture multiplying albedo at the hit, or NO_TEXTURE (texture.wgsl).
    color_texture: u32,
    // Texture whose x multiplies the roughness (alpha by x * x) and y metallic, or NO_TEXTURE.
    roughness_texture: u32,
    // PBR: the conductor's share.
    metallic: f32,
    // PBR: KHR_materials_specular's colour and factor for the dielectric layer.
    specular_color: vec3<f32>,
    specular: f32,
    // Texture multiplying emission at the hit (glTF's emissiveTexture), or NO_TEXTURE.
    emission_texture: u32,
    // Tangent-space normal map (glTF's normalTexture), or NO_TEXTURE; its x and y are scaled by
    // normal_scale (normal_map.wgsl).
    normal_texture: u32,
    normal_scale: f32,
    // glTF's alphaMode: ALPHA_OPAQUE, ALPHA_MASK or ALPHA_BLEND.
    alpha_mode: u32,
    // The base colour's alpha; the colour texture's alpha multiplies it. Read only where
    // alpha_mode is not opaque.
    opacity: f32,
    // MASK: a hit whose alpha is below this is no hit.
    alpha_cutoff: f32,
    // PBR: the share of the dielectric base that transmits (KHR_materials_transmission).
    transmission: f32,
    // Texture whose x (glTF's R channel) multiplies transmission, or NO_TEXTURE.
    transmission_texture: u32,
    // PBR with transmission: the colour white light has after attenuation_distance inside the
    // mesh (KHR_materials_volume, Beer-Lambert); distance 0 where there is none.
    attenuation_color: vec3<f32>,
    attenuation_distance: f32,
    // PBR: KHR_materials_clearcoat's layer (clearcoat.wgsl): its weight, its GGX alpha, and
    // textures whose x multiplies the weight and whose y the roughness (alpha by y * y).
    clearcoat: f32,
    clearcoat_alpha: f32,
    clearcoat_texture: u32,
    clearcoat_roughness_texture: u32,
    // The coat's own tangent-space normal map and its scale, or NO_TEXTURE.
    clearcoat_normal_texture: u32,
    clearcoat_normal_scale: f32,
    // PBR: KHR_materials_sheen (sheen.wgsl): the roughness (not squared) and textures
    // multiplying the colour (rgb) and the roughness (its alpha), or NO_TEXTURE.
    sheen_roughness: f32,
    sheen_color_texture: u32,
    // Black where there is no sheen.
    sheen_color: vec3<f32>,
    sheen_roughness_texture: u32,
}

const NO_TEXTURE: u32 = 0xffffffffu;

const PRIMITIVE_SPHERE: u32 = 0u;
const PRIMITIVE_QUAD: u32 = 1u;
const PRIMITIVE_TRIANGLE: u32 = 2u;

// A node of the light tree (src/kernel/types.rs): its emitters' box, power, normal cone
// (axis, cos theta_o), emission spread (cos theta_e) and whether any emits from both sides;
// the first child follows an interior node, `child` is its second; a leaf (child 0) holds one
// emitter (primitive, index).
struct LightTreeNode {
    lo: vec3<f32>,
    phi: f32,
    hi: vec3<f32>,
    cos_theta_o: f32,
    axis: vec3<f32>,
    cos_theta_e: f32,
    child: u32,
    primitive: u32,
    index: u32,
    two_sided: u32,
}

// A mesh triangle: what intersection and light sampling read. Its unit normal is
// normalize(cross(v1 - v0, v2 - v0)).
struct Triangle {
    v0: vec3<f32>,
    material: u32,
    v1: vec3<f32>,
    // Probability that light sampling picks this triangle (0 when it does not emit).
    light_probability: f32,
    v2: vec3<f32>,
    area: f32,
}

// A triangle's vertex normals, read only at the closest hit, for shading.
struct TriangleNormals {
    n0: vec3<f32>,
    // 1: interpolate the vertex normals; 0: flat (the geometric normal shades).
    smooth_shading: u32,
    n1: vec3<f32>,
    n2: vec3<f32>,
}

// A triangle's vertex tangents for normal mapping: xyz the unit tangent along increasing u, w
// the bitangent's sign (bitangent = w * cross(normal, tangent), along increasing v).
struct TriangleTangents {
    t0: vec4<f32>,
    t1: vec4<f32>,
    t2: vec4<f32>,
}

// A node of the flattened BVH (src/kernel/bvh/mod.rs). An inner node (count == 0) has its children at
// first and first + 1; a leaf holds bvh_primitives[first .. first + count].
struct BvhNode {
    min: vec3<f32>,
    first: u32,
    max: vec3<f32>,
    count: u32,
}

// A node of the 4-wide BVH (src/kernel/bvh/wide.rs): its up to four children's boxes, one axis
// bound per vector, and what each child is: an inner node at bvh_wide_nodes[first] (count == 0),
// a leaf holding bvh_primitives[first .. first + count], or none (count == WIDE_EMPTY_CHILD).
struct BvhWideNode {
    min_x: vec4<f32>,
    min_y: vec4<f32>,
    min_z: vec4<f32>,
    max_x: vec4<f32>,
    max_y: vec4<f32>,
    max_z: vec4<f32>,
    first: vec4<u32>,
    count: vec4<u32>,
}

const WIDE_EMPTY_CHILD: u32 = 0xffffffffu;

// A BVH leaf's primitive reference: the kind in the top two bits, the index below.
const PRIMITIVE_KIND_SHIFT: u32 = 30u;
const PRIMITIVE_INDEX_MASK: u32 = 0x3fffffffu;

// A top-level reference's kind for an instance; 3 is also PRIMITIVE_ENVIRONMENT, a light's kind
// that never appears in a leaf.
const PRIMITIVE_INSTANCE: u32 = 3u;
// ClosestPrimitive.instance of a primitive placed as it is.
const NO_INSTANCE: u32 = 0xffffffffu;

// A placement of an instanced mesh (src/kernel/types.rs says what each field holds).
struct Instance {
    to_world: array<vec4<f32>, 3>,
    to_object: array<vec4<f32>, 3>,
    blas_root: u32,
    first_triangle: u32,
    triangle_count: u32,
    _pad: u32,
}

// One entry per emitting primitive, for choosing one in proportion to its power.
// One entry per emitter and one slot of the alias table over them (src/kernel/types.rs).
struct Emitter {
    primitive: u32,
    index: u32,
    probability: f32,
    alias_threshold: f32,
    alias_primitive: u32,
    alias_index: u32,
    alias_probability: f32,
    _pad: u32,
}

const TEXTURE_IMAGE: u32 = 0u;
const TEXTURE_CHECKER: u32 = 1u;
const TEXTURE_WRAP_REPEAT: u32 = 0u;
const TEXTURE_WRAP_CLAMP: u32 = 1u;
const TEXTURE_WRAP_MIRROR: u32 = 2u;
const TEXTURE_NEAREST: u32 = 65536u;

// An image whose texels are texels[first_texel ..][.. width * height], bottom row first, or a
// checker of two colours with `scale` squares per unit of u and of v (texture.wgsl).
struct Texture {
    kind: u32,
    first_texel: u32,
    width: u32,
    height: u32,
    // The checker's colour where floor(u scale) + floor(v scale) is even (the origin's square).
    color0: vec3<f32>,
    scale: f32,
    color1: vec3<f32>,
    // Image lookups: TEXTURE_WRAP_* for u in bits 0-7 and for v in bits 8-15, and
    // TEXTURE_NEAREST for unfiltered lookups.
    sampling: u32,
    // The texture coordinates the lookup uses: (dot(transform_u, (u, v, 1)),
    // dot(transform_v, (u, v, 1))) (glTF's KHR_texture_transform; the identity otherwise).
    transform_u: vec3<f32>,
    // The texture coordinate set the lookup reads: 0, or 1 (glTF's TEXCOORD_1).
    uv_set: u32,
    transform_v: vec3<f32>,
}

// A triangle's texture coordinates at its three vertices (zero where the mesh has none).
struct TriangleUvs {
    uv0: vec2<f32>,
    uv1: vec2<f32>,
    uv2: vec2<f32>,
}

// A triangle's vertex colours (glTF's COLOR_0, linear RGBA; white where the mesh has none),
// multiplying the base colour and its alpha.
struct TriangleColors {
    c0: vec4<f32>,
    c1: vec4<f32>,
    c2: vec4<f32>,
}

// The emitter table's entry for the environment map (index 0).
const PRIMITIVE_ENVIRONMENT: u32 = 3u;

// One texel of the environment map: its radiance, and the solid-angle density with which
// environment sampling picks a direction in it (selection among emitters excluded).
struct EnvironmentTexel {
    radiance: vec3<f32>,
    pdf: f32,
}

// An entry of the alias table over the environment map's texels: texel k is kept with
// probability `threshold`, else texel `alias` is taken.
struct EnvironmentAlias {
    threshold: f32,
    alias_texel: u32,
}

struct Ray {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

// Binding 0, params: Params, is declared by the host, in a uniform or a storage buffer
// (src/gpu/inline_uniforms.rs says why).
// The scene's objects (bindings 1, 2, 3 and 6) are declared by scene_storage.wgsl or
// scene_uniform.wgsl, whichever the host chose (src/kernel/variant.rs).
// Per pixel, over all samples so far: the mean radiance (xyz; w unused) and M2, the sum of
// squared deviations from the mean (xyz), from which the variance follows. Running means and
// M2 stay accurate in f32 over millions of samples, where sums of squares would cancel.
@group(0) @binding(4) var<storage, read_write> accum_mean: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> accum_m2: array<vec4<f32>>;
// Ray segments traced (camera, bounce and shadow rays), for benchmarks; wraps at 2^32, so the
// host reads and clears it after each batch when it wants the figure.
@group(0) @binding(7) var<storage, read_write> segments_traced: atomic<u32>;

// The emitter table's entry for a point, spot or directional light (index into `lights`).
const PRIMITIVE_LIGHT: u32 = 4u;

const LIGHT_POINT: u32 = 0u;
const LIGHT_SPOT: u32 = 1u;
// A directional light: a delta sun when sun_one_minus_cos is 0, else a disk.
const LIGHT_SUN: u32 = 2u;

// A point, spot or directional light (src/kernel/types.rs says what each field holds).
struct Light {
    position: vec3<f32>,
    kind: u32,
    direction: vec3<f32>,
    light_probability: f32,
    emitted: vec3<f32>,
    spot_scale: f32,
    spot_offset: f32,
    sun_one_minus_cos: f32,
    _pad: vec2<u32>,
}
