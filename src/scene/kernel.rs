//! The validated scene laid out as the kernel's `#[repr(C)]` structs, and the emitter table
//! that light sampling draws from.

use super::{CameraBasis, MaterialKind, Scene, ROULETTE_START_BOUNCE};
use crate::shader_types::{
    self, Emitter, Params, MATERIAL_DIELECTRIC, MATERIAL_DIFFUSE, MATERIAL_METAL,
    MATERIAL_SPECULAR, PRIMITIVE_QUAD, PRIMITIVE_SPHERE, ROULETTE_OFF,
};

/// The scene as the kernel reads it; the CPU reference traces from the same structs.
#[derive(Clone, Debug)]
pub struct KernelScene {
    pub params: Params,
    pub spheres: Vec<shader_types::Sphere>,
    pub quads: Vec<shader_types::Quad>,
    pub materials: Vec<shader_types::Material>,
    pub emitters: Vec<Emitter>,
}

impl Scene {
    /// Converts to the kernel's structs (camera basis precomputed, quads' duals, emission × strength).
    pub fn kernel_scene(&self) -> KernelScene {
        let c = &self.camera;
        let r = &self.render;
        let CameraBasis {
            w,
            right: u,
            image_up: v,
        } = c.basis();
        let half_height = (c.vfov.to_radians() * 0.5).tan();
        let half_width = half_height * r.width as f32 / r.height as f32;
        let lens_radius = 0.5 * c.aperture;
        let (emitters, sphere_light_probability, quad_light_probability) = self.emitter_table();
        let params = Params {
            eye: c.eye.into(),
            width: r.width,
            forward: (-w).into(),
            height: r.height,
            right: (u * half_width).into(),
            sample_start: 0,
            up: (v * half_height).into(),
            sample_count: 0,
            background: r.background.into(),
            max_bounces: r.max_bounces,
            lens_right: (u * lens_radius).into(),
            focus_distance: c.focus_distance,
            lens_up: (v * lens_radius).into(),
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
            _pad: [0; 3],
        };
        let spheres = self
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| shader_types::Sphere {
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
                shader_types::Quad {
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
                let (kind, alpha, ior) = match m.kind {
                    MaterialKind::Diffuse => (MATERIAL_DIFFUSE, 0.0, 1.0),
                    MaterialKind::Specular => (MATERIAL_SPECULAR, 0.0, 1.0),
                    MaterialKind::Metal { roughness } => {
                        (MATERIAL_METAL, roughness * roughness, 1.0)
                    }
                    MaterialKind::Dielectric { ior } => (MATERIAL_DIELECTRIC, 0.0, ior),
                };
                shader_types::Material {
                    albedo: m.color.into(),
                    kind,
                    emission: m.emitted_radiance.into(),
                    alpha,
                    ior,
                    _pad: [0; 3],
                }
            })
            .collect();
        KernelScene {
            params,
            spheres,
            quads,
            materials,
            emitters,
        }
    }

    /// Every emitting primitive with its selection probability, proportional to its power
    /// (mean emitted radiance × area; the factor π is common to all), and that probability per
    /// sphere and per quad (0 for those that do not emit).
    fn emitter_table(&self) -> (Vec<Emitter>, Vec<f32>, Vec<f32>) {
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
        let total: f64 = powers.iter().map(|p| p.2).sum();
        let mut cumulative = 0.0;
        let mut emitters: Vec<Emitter> = powers
            .iter()
            .map(|&(primitive, index, power)| {
                cumulative += power / total;
                Emitter {
                    primitive,
                    index,
                    cdf: cumulative as f32,
                    probability: (power / total) as f32,
                }
            })
            .collect();
        if let Some(last) = emitters.last_mut() {
            last.cdf = 1.0;
        }
        let mut sphere_probability = vec![0.0; self.spheres.len()];
        let mut quad_probability = vec![0.0; self.quads.len()];
        for e in &emitters {
            let per_primitive = if e.primitive == PRIMITIVE_SPHERE {
                &mut sphere_probability
            } else {
                &mut quad_probability
            };
            per_primitive[e.index as usize] = e.probability;
        }
        (emitters, sphere_probability, quad_probability)
    }
}
