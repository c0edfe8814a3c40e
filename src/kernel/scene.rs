//! The validated scene laid out as the kernel's `#[repr(C)]` structs, and the emitter table
//! that light sampling draws from.

use crate::error::InputError;
use crate::kernel::bvh;
use crate::kernel::emitters::EmissionMeans;
use crate::kernel::types::{
    self, BvhNode, BvhWideNode, Emitter, EnvironmentAlias, EnvironmentTexel, Params, Texture,
    TriangleColors, TriangleNormals, TriangleTangents, TriangleUvs, ALPHA_BLEND, ALPHA_MASK,
    ALPHA_OPAQUE, MATERIAL_DIELECTRIC, MATERIAL_DIFFUSE, MATERIAL_METAL, MATERIAL_PBR,
    MATERIAL_SPECULAR, MATERIAL_UNLIT, NO_TEXTURE, PRIMITIVE_ENVIRONMENT, PRIMITIVE_LIGHT,
    PRIMITIVE_QUAD, PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE, ROULETTE_OFF,
};
use crate::scene::environment;
use crate::scene::light::LightKind;
use crate::scene::{AlphaMode, Camera, CameraBasis, MaterialKind, Scene, ROULETTE_START_BOUNCE};
use glam::{Vec2, Vec3, Vec4};

/// An instance's transforms as the kernel reads them: `placement`'s rows, and its inverse's,
/// inverted in f64 so the two agree to f32's precision.
fn kernel_instance(placement: &glam::Mat4, first_triangle: u32, count: u32) -> types::Instance {
    let inverse = placement.as_dmat4().inverse().as_mat4();
    let rows = |m: &glam::Mat4| [0, 1, 2].map(|i| m.row(i).to_array());
    types::Instance {
        to_world: rows(placement),
        to_object: rows(&inverse),
        blas_root: 0,
        first_triangle,
        triangle_count: count,
        _pad: 0,
    }
}

/// The box, in the scene's coordinates, of a mesh whose own box is (low, high) placed by
/// `placement`: its eight corners placed, and widened a little, since a ray is tested against
/// the mesh in the mesh's coordinates, so a hit on the box's boundary may round to just
/// outside the exact placed box (a larger box costs a little time, never a hit).
fn placed_box(placement: &glam::Mat4, low: Vec3, high: Vec3) -> (Vec3, Vec3) {
    let m = placement.as_dmat4();
    let (mut min, mut max) = (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY);
    for corner in 0..8 {
        let pick = |bit: usize, axis: usize| {
            if corner & bit != 0 {
                high[axis]
            } else {
                low[axis]
            }
        };
        let p = m.transform_point3(glam::DVec3::new(
            pick(1, 0) as f64,
            pick(2, 1) as f64,
            pick(4, 2) as f64,
        ));
        (min, max) = (min.min(p), max.max(p));
    }
    let margin = 1e-5 * ((max - min).max_element() + min.abs().max(max.abs()).max_element());
    ((min - margin).as_vec3(), (max + margin).as_vec3())
}

/// The scene as the kernel reads it; the CPU reference traces from the same structs.
#[derive(Clone, Debug)]
pub struct KernelScene {
    pub params: Params,
    pub spheres: Vec<types::Sphere>,
    pub quads: Vec<types::Quad>,
    pub materials: Vec<types::Material>,
    pub emitters: Vec<Emitter>,
    pub triangles: Vec<types::Triangle>,
    /// One per triangle.
    pub triangle_normals: Vec<TriangleNormals>,
    /// The BVH over all primitives; empty for scenes small enough to test every primitive
    /// (see [`bvh::wants_bvh`]).
    pub bvh_nodes: Vec<BvhNode>,
    pub bvh_primitives: Vec<u32>,
    /// The same tree collapsed 4 wide (`bvh_wide.rs`), over the same `bvh_primitives`; empty
    /// with no BVH. Each device traverses one of the two (`kernel::bvh::layout`).
    pub bvh_wide_nodes: Vec<BvhWideNode>,
    pub bvh_build_seconds: f64,
    /// Texture descriptors and all images' texels (`scene::texture`); empty without textures.
    pub textures: Vec<Texture>,
    pub texels: Vec<[f32; 4]>,
    /// One per triangle when the scene has textures, else empty.
    pub triangle_uvs: Vec<TriangleUvs>,
    /// The second set (glTF's TEXCOORD_1), one per triangle when a texture reads it, else
    /// empty.
    pub triangle_uvs1: Vec<TriangleUvs>,
    /// One per triangle when a material has a normal map, else empty.
    pub triangle_tangents: Vec<TriangleTangents>,
    /// One per triangle when a mesh has vertex colours, else empty.
    pub triangle_colors: Vec<TriangleColors>,
    /// The environment map's texels and alias table (`environment.rs`); empty without one.
    pub environment_texels: Vec<EnvironmentTexel>,
    pub environment_alias: Vec<EnvironmentAlias>,
    /// Point, spot and directional lights (`scene::light`); point lights with a radius are
    /// spheres instead.
    pub lights: Vec<types::Light>,
    /// The placements of instanced meshes (`Scene::instanced`), whose triangles follow the
    /// scene's own in `triangles` and whose bottom-level BVHs follow the top level in
    /// `bvh_nodes`; empty without instances.
    pub instances: Vec<types::Instance>,
}

impl KernelScene {
    /// Bytes of the scene's arrays on the device (all but the image's accumulators).
    pub fn scene_bytes(&self) -> u64 {
        fn bytes<T>(items: &[T]) -> u64 {
            std::mem::size_of_val(items) as u64
        }
        bytes(&self.spheres)
            + bytes(&self.quads)
            + bytes(&self.materials)
            + bytes(&self.emitters)
            + bytes(&self.triangles)
            + bytes(&self.triangle_normals)
            + bytes(&self.bvh_nodes)
            + bytes(&self.bvh_primitives)
            + bytes(&self.bvh_wide_nodes)
            + bytes(&self.textures)
            + bytes(&self.texels)
            + bytes(&self.triangle_uvs)
            + bytes(&self.triangle_uvs1)
            + bytes(&self.triangle_tangents)
            + bytes(&self.triangle_colors)
            + bytes(&self.environment_texels)
            + bytes(&self.environment_alias)
            + bytes(&self.lights)
            + bytes(&self.instances)
    }
}

/// Writes `camera` into `params` for its image size (`params.width`, `params.height`): the
/// basis precomputed, image-right and image-up scaled to half the viewport at unit distance
/// (perspective) or to half the view in world units (orthographic), and the lens. Apart from
/// the rest so the viewer can move the camera without rebuilding the scene's arrays (the BVH,
/// the environment map's tables).
pub fn place_camera(params: &mut Params, camera: &Camera) {
    use crate::scene::Projection;
    let CameraBasis {
        w,
        right: u,
        image_up: v,
    } = camera.basis();
    let (projection, half_height) = match camera.projection {
        Projection::Perspective { vfov } => (
            types::PROJECTION_PERSPECTIVE,
            (vfov.to_radians() * 0.5).tan(),
        ),
        Projection::Orthographic { height } => (types::PROJECTION_ORTHOGRAPHIC, 0.5 * height),
    };
    params.projection = projection;
    let half_width = half_height * params.width as f32 / params.height as f32;
    let lens_radius = 0.5 * camera.aperture;
    params.eye = camera.eye.into();
    params.forward = (-w).into();
    params.right = (u * half_width).into();
    params.up = (v * half_height).into();
    params.lens_right = (u * lens_radius).into();
    params.lens_up = (v * lens_radius).into();
    params.focus_distance = camera.focus_distance;
}

impl Scene {
    /// [`Scene::try_kernel_scene`] for scenes known to fit the kernel (tests, the built-in
    /// benchmark scene); panics where that one returns an error.
    pub fn kernel_scene(&self) -> KernelScene {
        self.try_kernel_scene().unwrap_or_else(|e| panic!("{e}"))
    }

    /// Converts to the kernel's structs (camera basis precomputed, quads' duals, emission ×
    /// strength, the BVH). Fails (bad input) when there are more primitives than the BVH can
    /// reference.
    pub fn try_kernel_scene(&self) -> Result<KernelScene, InputError> {
        if self.lights.iter().any(|l| l.sphere().is_some()) {
            return self.with_sphere_lights().lay_out();
        }
        self.lay_out()
    }

    /// The scene with each point light that has a radius turned into an emitting sphere, with
    /// a material of its own (`lights[i]`), which the kernel traces like any other sphere.
    fn with_sphere_lights(&self) -> Scene {
        let mut scene = self.clone();
        scene.lights.clear();
        for (i, light) in self.lights.iter().enumerate() {
            let Some((center, radius, radiance)) = light.sphere() else {
                scene.lights.push(light.clone());
                continue;
            };
            scene.spheres.push(crate::scene::Sphere {
                center,
                radius,
                material: scene.materials.len() as u32,
            });
            scene.materials.push(crate::scene::Material {
                name: format!("lights[{i}]"),
                kind: MaterialKind::Diffuse,
                color: Vec3::ZERO,
                emitted_radiance: radiance,
                color_texture: None,
                roughness_texture: None,
                emission_texture: None,
                normal_texture: None,
                alpha: crate::scene::Alpha::OPAQUE,
            });
        }
        scene
    }

    fn lay_out(&self) -> Result<KernelScene, InputError> {
        let r = &self.render;
        // Every triangle the kernel holds: the scene's own, then each instanced mesh's once, in
        // its own coordinates. Per-triangle arrays are indexed alike; instanced meshes never
        // emit (validate/objects.rs), so light sampling reads only the first part.
        let stored: Vec<&crate::scene::Triangle> = self
            .triangles
            .iter()
            .chain(self.instanced.iter().flat_map(|m| &m.triangles))
            .collect();
        let environment = self.environment.as_ref().map(|e| (e, e.tables()));
        let EmitterTable {
            emitters,
            sphere_probability: sphere_light_probability,
            quad_probability: quad_light_probability,
            triangle_probability: triangle_light_probability,
            light_probability,
        } = self.emitter_table(environment.as_ref().map(|(_, t)| t.radiance_integral));
        let (environment_cos, environment_sin) = environment
            .as_ref()
            .map_or((1.0, 0.0), |(e, _)| e.rotation());
        let mut params = Params {
            width: r.width,
            height: r.height,
            sample_start: 0,
            sample_count: 0,
            background: r.background.into(),
            max_bounces: r.max_bounces,
            light_sampling: r.light_sampling as u32,
            seed: r.seed,
            sphere_count: self.spheres.len() as u32,
            quad_count: self.quads.len() as u32,
            material_count: self.materials.len() as u32,
            emitter_count: emitters.len() as u32,
            roulette_start: if r.russian_roulette {
                ROULETTE_START_BOUNCE
            } else {
                ROULETTE_OFF
            },
            accumulated_samples: 0,
            aovs: 0,
            radiance_clamp: 0.0,
            // The scan's: the triangles placed as they are (instanced ones follow them).
            triangle_count: self.triangles.len() as u32,
            environment_width: environment.as_ref().map_or(0, |(e, _)| e.image.width),
            environment_height: environment.as_ref().map_or(0, |(e, _)| e.image.height),
            environment_cos,
            environment_sin,
            environment_light_probability: emitters
                .iter()
                .find(|e| e.primitive == PRIMITIVE_ENVIRONMENT)
                .map_or(0.0, |e| e.probability),
            light_count: self.lights.len() as u32,
            ..Default::default()
        };
        place_camera(&mut params, &self.camera);
        let spheres = self
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| types::Sphere {
                center: s.center.into(),
                radius: s.radius,
                material: s.material,
                light_probability: sphere_light_probability[i],
                _pad: [0; 2],
            })
            .collect();
        let quads = self
            .quads
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let cross = q.u.cross(q.v);
                let normal = cross.normalize();
                types::Quad {
                    corner: q.corner.into(),
                    material: q.material,
                    edge_u: q.u.into(),
                    area: cross.length(),
                    edge_v: q.v.into(),
                    plane_offset: normal.dot(q.corner),
                    normal: normal.into(),
                    light_probability: quad_light_probability[i],
                    u_dual: (q.u / q.u.dot(q.u)).into(),
                    v_dual: (q.v / q.v.dot(q.v)).into(),
                    ..Default::default()
                }
            })
            .collect();
        let materials = self
            .materials
            .iter()
            .map(|m| {
                let (mut metallic, mut specular, mut specular_color) = (0.0, 0.0, Vec3::ZERO);
                // No transmission nor attenuation but where a pbr material asks for them.
                let (mut transmission, mut transmission_texture) = (0.0, NO_TEXTURE);
                let (mut attenuation_color, mut attenuation_distance) = (Vec3::ONE, 0.0);
                let mut layers = crate::scene::PbrLayers::default();
                let (kind, alpha, ior) = match m.kind {
                    MaterialKind::Diffuse => (MATERIAL_DIFFUSE, 0.0, 1.0),
                    MaterialKind::Unlit => (MATERIAL_UNLIT, 0.0, 1.0),
                    MaterialKind::Specular => (MATERIAL_SPECULAR, 0.0, 1.0),
                    MaterialKind::Metal { roughness } => {
                        (MATERIAL_METAL, roughness * roughness, 1.0)
                    }
                    MaterialKind::Dielectric { ior } => (MATERIAL_DIELECTRIC, 0.0, ior),
                    MaterialKind::Pbr {
                        roughness,
                        metallic: m,
                        ior,
                        specular: s,
                        specular_color: c,
                        transmission: t,
                        transmission_texture: t_texture,
                        attenuation_color: a_color,
                        attenuation_distance: a_distance,
                        layers: l,
                    } => {
                        layers = l;
                        (metallic, specular, specular_color) = (m, s, c);
                        (transmission, transmission_texture) = (t, t_texture.unwrap_or(NO_TEXTURE));
                        if let Some(d) = a_distance {
                            (attenuation_color, attenuation_distance) = (a_color, d);
                        }
                        (MATERIAL_PBR, roughness * roughness, ior)
                    }
                };
                types::Material {
                    albedo: m.color.into(),
                    kind,
                    emission: m.emitted_radiance.into(),
                    alpha,
                    ior,
                    color_texture: m.color_texture.unwrap_or(NO_TEXTURE),
                    roughness_texture: m.roughness_texture.unwrap_or(NO_TEXTURE),
                    metallic,
                    specular_color: specular_color.into(),
                    specular,
                    emission_texture: m.emission_texture.unwrap_or(NO_TEXTURE),
                    normal_texture: m.normal_texture.map_or(NO_TEXTURE, |(t, _)| t),
                    normal_scale: m.normal_texture.map_or(1.0, |(_, s)| s),
                    alpha_mode: match m.alpha.mode {
                        AlphaMode::Opaque => ALPHA_OPAQUE,
                        AlphaMode::Mask { .. } => ALPHA_MASK,
                        AlphaMode::Blend => ALPHA_BLEND,
                    },
                    opacity: m.alpha.opacity,
                    alpha_cutoff: match m.alpha.mode {
                        AlphaMode::Mask { cutoff } => cutoff,
                        // glTF's default, unread.
                        AlphaMode::Opaque | AlphaMode::Blend => 0.5,
                    },
                    transmission,
                    transmission_texture,
                    attenuation_color: attenuation_color.into(),
                    attenuation_distance,
                    clearcoat: layers.clearcoat,
                    clearcoat_alpha: layers.clearcoat_roughness * layers.clearcoat_roughness,
                    clearcoat_texture: layers.clearcoat_texture.unwrap_or(NO_TEXTURE),
                    clearcoat_roughness_texture: layers
                        .clearcoat_roughness_texture
                        .unwrap_or(NO_TEXTURE),
                    clearcoat_normal_texture: layers
                        .clearcoat_normal_texture
                        .map_or(NO_TEXTURE, |(t, _)| t),
                    clearcoat_normal_scale: layers.clearcoat_normal_texture.map_or(1.0, |(_, s)| s),
                    sheen_roughness: layers.sheen_roughness,
                    sheen_color_texture: layers.sheen_color_texture.unwrap_or(NO_TEXTURE),
                    sheen_color: layers.sheen_color.into(),
                    sheen_roughness_texture: layers.sheen_roughness_texture.unwrap_or(NO_TEXTURE),
                }
            })
            .collect();
        let triangles: Vec<types::Triangle> = stored
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let [a, b, c] = t.vertices;
                types::Triangle {
                    v0: a.into(),
                    material: t.material,
                    v1: b.into(),
                    light_probability: triangle_light_probability.get(i).copied().unwrap_or(0.0),
                    v2: c.into(),
                    area: 0.5 * (b - a).cross(c - a).length(),
                }
            })
            .collect();
        let triangle_normals = stored
            .iter()
            .map(|t| match t.normals {
                Some([n0, n1, n2]) => TriangleNormals {
                    n0: n0.into(),
                    smooth_shading: 1,
                    n1: n1.into(),
                    n2: n2.into(),
                    ..Default::default()
                },
                None => TriangleNormals::default(),
            })
            .collect();
        let mut scene = KernelScene {
            params,
            spheres,
            quads,
            materials,
            emitters,
            triangles,
            triangle_normals,
            bvh_nodes: Vec::new(),
            bvh_primitives: Vec::new(),
            bvh_wide_nodes: Vec::new(),
            bvh_build_seconds: 0.0,
            textures: self.textures.descriptors.clone(),
            texels: self.textures.texels.clone(),
            triangle_uvs: if self.textures.is_empty() {
                Vec::new()
            } else {
                stored
                    .iter()
                    .map(|t| {
                        let [uv0, uv1, uv2] = t.uvs.unwrap_or_default().map(|uv| uv.into());
                        TriangleUvs { uv0, uv1, uv2 }
                    })
                    .collect()
            },
            triangle_uvs1: if self.textures.descriptors.iter().any(|t| t.uv_set == 1) {
                stored
                    .iter()
                    .map(|t| {
                        let [uv0, uv1, uv2] = t.uvs1.unwrap_or_default().map(|uv| uv.into());
                        TriangleUvs { uv0, uv1, uv2 }
                    })
                    .collect()
            } else {
                Vec::new()
            },
            triangle_tangents: if self.materials.iter().any(|m| m.has_normal_map()) {
                stored
                    .iter()
                    .map(|t| {
                        let [t0, t1, t2] = t.tangents.unwrap_or_default().map(|t| t.into());
                        TriangleTangents { t0, t1, t2 }
                    })
                    .collect()
            } else {
                Vec::new()
            },
            // White where a triangle has none: the colours multiply.
            triangle_colors: if stored.iter().any(|t| t.colors.is_some()) {
                stored
                    .iter()
                    .map(|t| {
                        let [c0, c1, c2] = t.colors.unwrap_or([Vec4::ONE; 3]).map(|c| c.into());
                        TriangleColors { c0, c1, c2 }
                    })
                    .collect()
            } else {
                Vec::new()
            },
            environment_texels: Vec::new(),
            environment_alias: Vec::new(),
            lights: self
                .lights
                .iter()
                .zip(light_probability)
                .map(|(l, p)| l.kernel_light(p))
                .collect(),
            instances: Vec::new(),
        };
        if let Some((_, tables)) = environment {
            scene.environment_texels = tables.texels;
            scene.environment_alias = tables.alias;
        }
        if bvh::wants_bvh(
            scene.spheres.len(),
            scene.quads.len(),
            scene.triangles.len(),
        ) {
            // Validation bounds the primitive count far below what a reference holds, and the
            // builder bounds the tree's depth by the traversal stack: this error is a backstop.
            let cannot = |e: String| InputError(format!("the scene cannot be rendered: {e}"));
            let tree = if self.instanced.is_empty() {
                bvh::build(&scene.spheres, &scene.quads, &scene.triangles).map_err(cannot)?
            } else {
                let (tree, instances) = self.two_level(&scene).map_err(cannot)?;
                scene.instances = instances;
                tree
            };
            // The wide tree only without instances: its traversal has no instance leaves, and
            // an instance's mesh is walked in the binary tree (shaders/traverse/blas.wgsl),
            // which the wide variant does not bind. Scenes with instances keep the binary one.
            if scene.instances.is_empty() {
                scene.bvh_wide_nodes = tree.wide_nodes();
            }
            scene.bvh_nodes = tree.nodes;
            scene.bvh_primitives = tree.primitives;
            scene.bvh_build_seconds = tree.build_seconds;
        }
        Ok(scene)
    }

    /// The two-level structure over `scene`'s primitives (laid out by [`Scene::lay_out`]): the
    /// top-level BVH over the spheres, quads and triangles placed as they are and one leaf
    /// primitive per instance, then each instanced mesh's own BVH after it in the same
    /// arrays, and the instances' transforms. Memory grows with unique geometry: a mesh's
    /// triangles and BVH are stored once, whatever its number of instances.
    fn two_level(&self, scene: &KernelScene) -> Result<(bvh::Bvh, Vec<types::Instance>), String> {
        let own = self.triangles.len();
        let mut first_triangle = own as u32;
        let mut instances = Vec::new();
        let mut boxes = Vec::new();
        // Each mesh's bottom level is built now and appended once the top level is laid out.
        let mut meshes = Vec::with_capacity(self.instanced.len());
        for mesh in &self.instanced {
            let count = mesh.triangles.len();
            let range = first_triangle as usize..first_triangle as usize + count;
            let bottom = bvh::build(&[], &[], &scene.triangles[range.clone()])?;
            let root = &bottom.nodes[0];
            let (low, high) = (Vec3::from(root.min), Vec3::from(root.max));
            for placement in &mesh.placements {
                boxes.push(placed_box(placement, low, high));
                instances.push(kernel_instance(placement, first_triangle, count as u32));
            }
            meshes.push((
                instances.len() - mesh.placements.len()..instances.len(),
                range,
            ));
            first_triangle += count as u32;
        }
        let mut tree = bvh::build_top_level(
            &scene.spheres,
            &scene.quads,
            &scene.triangles[..own],
            &boxes,
        )?;
        for (placed, range) in meshes {
            let first = range.start as u32;
            let root = bvh::append_bottom_level(&mut tree, &scene.triangles[range], first)?;
            for instance in &mut instances[placed] {
                instance.blas_root = root;
            }
        }
        Ok((tree, instances))
    }

    /// Every emitting primitive with its selection probability, proportional to its power
    /// (mean emitted radiance × area; the factor π is common to all), as Vose's alias table
    /// (the environment map's, [`environment::alias_table`]), and that probability per
    /// sphere, per quad and per triangle (0 for those that do not emit). The environment map,
    /// given its ∫ L dω, emits that through a disc the size of the scene: π R² ∫ L dω, whose π
    /// is dropped as for the others (pbrt's ImageInfiniteLight::Phi); so does a sun
    /// (`Light::power`).
    fn emitter_table(&self, environment_radiance_integral: Option<f64>) -> EmitterTable {
        let radiance = |material: u32| self.materials[material as usize].emitted_radiance;
        let mut powers: Vec<(u32, u32, f64)> = Vec::new();
        for (i, s) in self.spheres.iter().enumerate() {
            let power = radiance(s.material).element_sum() as f64 / 3.0
                * 4.0
                * std::f64::consts::PI
                * (s.radius as f64).powi(2);
            if power > 0.0 {
                powers.push((PRIMITIVE_SPHERE, i as u32, power));
            }
        }
        for (i, q) in self.quads.iter().enumerate() {
            let power =
                radiance(q.material).element_sum() as f64 / 3.0 * q.u.cross(q.v).length() as f64;
            if power > 0.0 {
                powers.push((PRIMITIVE_QUAD, i as u32, power));
            }
        }
        let mut textured = EmissionMeans::new(&self.textures);
        for (i, t) in self.triangles.iter().enumerate() {
            let [a, b, c] = t.vertices;
            let m = &self.materials[t.material as usize];
            let mean = match m.emission_texture {
                Some(texture) if m.emitted_radiance != Vec3::ZERO => textured.triangle_mean(
                    m.emitted_radiance,
                    texture,
                    t.uvs.unwrap_or([Vec2::ZERO; 3]),
                ),
                _ => radiance(t.material).element_sum() as f64 / 3.0,
            };
            // An unlit triangle's vertex colour multiplies what it emits: its mean over the
            // triangle (the corners' mean) estimates the product's.
            let color_mean = match t.colors {
                Some(colors) if matches!(m.kind, MaterialKind::Unlit) => {
                    colors
                        .iter()
                        .map(|c| c.truncate())
                        .sum::<Vec3>()
                        .element_sum() as f64
                        / 9.0
                }
                _ => 1.0,
            };
            let power = mean * color_mean * 0.5 * (b - a).cross(c - a).length() as f64;
            if power > 0.0 {
                powers.push((PRIMITIVE_TRIANGLE, i as u32, power));
            }
        }
        let has_sun = self
            .lights
            .iter()
            .any(|l| matches!(l.kind, LightKind::Directional { .. }));
        let mut scene_radius = 1.0;
        if environment_radiance_integral.is_some() || has_sun {
            let points = self
                .spheres
                .iter()
                .flat_map(|s| {
                    [
                        s.center - Vec3::splat(s.radius),
                        s.center + Vec3::splat(s.radius),
                    ]
                })
                .chain(self.quads.iter().flat_map(|q| {
                    [
                        q.corner,
                        q.corner + q.u,
                        q.corner + q.v,
                        q.corner + q.u + q.v,
                    ]
                }))
                .chain(self.triangles.iter().flat_map(|t| t.vertices))
                // An instanced mesh's placed box, not its placed vertices, which may be 10¹⁰:
                // a bound a little larger than the flattened scene's.
                .chain(self.instanced.iter().flat_map(|m| {
                    let low = m
                        .triangles
                        .iter()
                        .flat_map(|t| t.vertices)
                        .fold(Vec3::INFINITY, Vec3::min);
                    let high = m
                        .triangles
                        .iter()
                        .flat_map(|t| t.vertices)
                        .fold(Vec3::NEG_INFINITY, Vec3::max);
                    m.placements.iter().flat_map(move |p| {
                        (0..8).map(move |c| {
                            let corner = Vec3::select(
                                glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0),
                                high,
                                low,
                            );
                            p.transform_point3(corner)
                        })
                    })
                }))
                .chain(self.lights.iter().filter_map(|l| match l.kind {
                    LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                        Some(position)
                    }
                    LightKind::Directional { .. } => None,
                }));
            scene_radius = environment::scene_radius(points);
        }
        if let Some(integral) = environment_radiance_integral {
            let power = scene_radius.powi(2) * integral;
            if power > 0.0 {
                powers.push((PRIMITIVE_ENVIRONMENT, 0, power));
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            let power = l.power(scene_radius);
            if power > 0.0 {
                powers.push((PRIMITIVE_LIGHT, i as u32, power));
            }
        }
        let total: f64 = powers.iter().map(|p| p.2).sum();
        let mut emitters: Vec<Emitter> = powers
            .iter()
            .map(|&(primitive, index, power)| Emitter {
                primitive,
                index,
                probability: (power / total) as f32,
                ..Default::default()
            })
            .collect();
        let weights: Vec<f64> = powers.iter().map(|p| p.2).collect();
        for (slot, alias) in environment::alias_table(&weights).iter().enumerate() {
            let other = emitters[alias.alias_texel as usize];
            let e = &mut emitters[slot];
            e.alias_threshold = alias.threshold;
            e.alias_primitive = other.primitive;
            e.alias_index = other.index;
            e.alias_probability = other.probability;
        }
        let mut sphere_probability = vec![0.0; self.spheres.len()];
        let mut quad_probability = vec![0.0; self.quads.len()];
        let mut triangle_probability = vec![0.0; self.triangles.len()];
        let mut light_probability = vec![0.0; self.lights.len()];
        for e in &emitters {
            let per_primitive = match e.primitive {
                PRIMITIVE_SPHERE => &mut sphere_probability,
                PRIMITIVE_QUAD => &mut quad_probability,
                PRIMITIVE_TRIANGLE => &mut triangle_probability,
                PRIMITIVE_LIGHT => &mut light_probability,
                _ => continue,
            };
            per_primitive[e.index as usize] = e.probability;
        }
        EmitterTable {
            emitters,
            sphere_probability,
            quad_probability,
            triangle_probability,
            light_probability,
        }
    }
}

/// The emitters (light sampling's alias table), and the probability of picking each sphere,
/// quad, triangle and light (0 for those that do not emit).
struct EmitterTable {
    emitters: Vec<Emitter>,
    sphere_probability: Vec<f32>,
    quad_probability: Vec<f32>,
    triangle_probability: Vec<f32>,
    light_probability: Vec<f32>,
}
