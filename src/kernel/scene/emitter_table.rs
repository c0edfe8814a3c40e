//! The emitter table light sampling draws from: every emitting sphere, quad and triangle, the
//! environment map and each light, picked in proportion to its power through Vose's alias
//! table; and each primitive's probability of being picked, which the kernel reads where a
//! path hits it (multiple importance sampling). Textured emitters' mean radiance comes from
//! `kernel::emitters`.

use crate::kernel::emitters::EmissionMeans;
use crate::kernel::types::{
    Emitter, PRIMITIVE_ENVIRONMENT, PRIMITIVE_LIGHT, PRIMITIVE_QUAD, PRIMITIVE_SPHERE,
    PRIMITIVE_TRIANGLE,
};
use crate::scene::environment;
use crate::scene::light::LightKind;
use crate::scene::{InstancedMesh, MaterialKind, Scene, Triangle};
use glam::{Vec2, Vec3};

/// An emitter before the table: its primitive kind (`PRIMITIVE_*`), its index among those,
/// and its power (above 0).
pub(super) type Power = (u32, u32, f64);

/// The emitters (light sampling's alias table), and the probability of picking each sphere,
/// quad, triangle and light (0 for those that do not emit).
pub(super) struct EmitterTable {
    pub(super) emitters: Vec<Emitter>,
    pub(super) sphere_probability: Vec<f32>,
    pub(super) quad_probability: Vec<f32>,
    pub(super) triangle_probability: Vec<f32>,
    pub(super) light_probability: Vec<f32>,
    /// The finite emitters' powers (all but the environment map and suns): what the light
    /// tree is built over (`light_tree.rs`).
    pub(super) finite: Vec<Power>,
    /// The probability of picking one of them.
    pub(super) finite_probability: f32,
}

impl Scene {
    /// Every emitting primitive with its selection probability, proportional to its power
    /// (mean emitted radiance × area; the factor π is common to all), as Vose's alias table
    /// (the environment map's, [`environment::alias_table`]), and that probability per
    /// sphere, per quad and per triangle (0 for those that do not emit). The environment map,
    /// given its ∫ L dω, emits that through a disc the size of the scene: π R² ∫ L dω, whose π
    /// is dropped as for the others (pbrt's ImageInfiniteLight::Phi); so does a sun
    /// (`Light::power`).
    pub(super) fn emitter_table(&self, environment_radiance_integral: Option<f64>) -> EmitterTable {
        let mut powers = self.primitive_powers();
        let has_sun = self
            .lights
            .iter()
            .any(|l| matches!(l.kind, LightKind::Directional { .. }));
        let mut scene_radius = 1.0;
        if environment_radiance_integral.is_some() || has_sun {
            scene_radius = environment::scene_radius(self.bounding_points());
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
        let finite: Vec<Power> = powers
            .iter()
            .copied()
            .filter(|&(primitive, index, _)| match primitive {
                PRIMITIVE_ENVIRONMENT => false,
                PRIMITIVE_LIGHT => !matches!(
                    self.lights[index as usize].kind,
                    LightKind::Directional { .. }
                ),
                _ => true,
            })
            .collect();
        let total: f64 = powers.iter().map(|p| p.2).sum();
        let finite_power: f64 = finite.iter().map(|p| p.2).sum();
        let emitters = alias_table(&powers);
        let mut table = self.per_primitive_probabilities(emitters);
        table.finite_probability = if finite_power == total {
            1.0
        } else {
            (finite_power / total) as f32
        };
        table.finite = finite;
        table
    }

    /// The emitting spheres, quads and triangles (the scene's own: instanced meshes never
    /// emit), in that order, with their powers.
    pub(super) fn primitive_powers(&self) -> Vec<Power> {
        let radiance = |material: u32| self.materials[material as usize].emitted_radiance;
        let mut powers: Vec<Power> = Vec::new();
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
            let power = self.triangle_power(t, &mut textured);
            if power > 0.0 {
                powers.push((PRIMITIVE_TRIANGLE, i as u32, power));
            }
        }
        powers
    }

    /// A triangle's power: its mean emitted radiance (over its emission texture's texels where
    /// it has one, `textured`), times its vertex colours' mean where it is unlit, × its area.
    fn triangle_power(&self, t: &Triangle, textured: &mut EmissionMeans) -> f64 {
        let [a, b, c] = t.vertices;
        let m = &self.materials[t.material as usize];
        let mean = match m.emission_texture {
            Some(texture) if m.emitted_radiance != Vec3::ZERO => textured.triangle_mean(
                m.emitted_radiance,
                texture,
                t.uvs.unwrap_or([Vec2::ZERO; 3]),
            ),
            _ => m.emitted_radiance.element_sum() as f64 / 3.0,
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
        mean * color_mean * 0.5 * (b - a).cross(c - a).length() as f64
    }

    /// Points whose bounds hold the scene, for [`environment::scene_radius`]: the spheres'
    /// boxes' corners, the quads' and triangles' corners, the instanced meshes' placed boxes'
    /// corners, and the point and spot lights' positions.
    /// The centre and radius of a sphere around every surface and light (the box's, as
    /// `environment::scene_radius` measures it): where light paths from infinitely far
    /// lights start.
    pub(super) fn bounding_sphere(&self) -> ([f32; 3], f32) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in self.bounding_points() {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if lo.x > hi.x {
            return ([0.0; 3], 1.0);
        }
        let radius = environment::scene_radius([lo, hi].into_iter()) as f32;
        ((0.5 * (lo + hi)).into(), radius)
    }

    fn bounding_points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.spheres
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
            .chain(self.instanced.iter().flat_map(placed_box_corners))
            .chain(self.lights.iter().filter_map(|l| match l.kind {
                LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                    Some(position)
                }
                LightKind::Directional { .. } => None,
            }))
    }

    /// Each sphere's, quad's, triangle's and light's probability of being picked from
    /// `emitters`, which the table then holds.
    fn per_primitive_probabilities(&self, emitters: Vec<Emitter>) -> EmitterTable {
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
            finite: Vec::new(),
            finite_probability: 0.0,
        }
    }
}

/// The corners of an instanced mesh's box at each of its placements: its placed box, not its
/// placed vertices, which may be 10¹⁰: a bound a little larger than the flattened scene's.
fn placed_box_corners(m: &InstancedMesh) -> impl Iterator<Item = Vec3> + '_ {
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
}

/// The emitters of `powers`, each picked with probability power / total, with Vose's alias
/// table over them: each slot's alias is another emitter, whose probability it carries too.
fn alias_table(powers: &[Power]) -> Vec<Emitter> {
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
    emitters
}
