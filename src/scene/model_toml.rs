//! A model scene (`model.rs`) written as a scene file (`glint render model.glb
//! --print-scene`): saved next to the model, it renders the same image. The camera and the
//! lights are written out, so they can be edited (the mesh entry says `lights = false`, so
//! the file's lights are not added twice). Numbers are written as Rust's shortest
//! round-tripping form of each f32, so they read back bit for bit.

use super::light::{Light, LightKind};
use super::model::{EnvironmentSource, ModelScene, DEFAULT_COLOR, DEFAULT_MATERIAL};
use super::studio;
use super::Projection;
use glam::Vec3;
use std::fmt::Write;

fn real(x: f32) -> String {
    format!("{x:?}")
}

fn triple(v: Vec3) -> String {
    format!("[{}, {}, {}]", real(v.x), real(v.y), real(v.z))
}

fn string(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// The scene file text.
pub fn model_toml(model: &ModelScene) -> String {
    let scene = &model.scene;
    let mut out = String::new();
    let file = &model.file_name;
    let _ = writeln!(
        out,
        "# The scene glint builds from {file}.\n\
         # Save it next to {file} (as a .toml file) and render it to get the same image.\n"
    );
    let c = &scene.camera;
    let _ = writeln!(out, "[camera]");
    let _ = writeln!(out, "eye = {}", triple(c.eye));
    let _ = writeln!(out, "target = {}", triple(c.target));
    let _ = writeln!(out, "up = {}", triple(c.up));
    match c.projection {
        Projection::Perspective { vfov } => {
            let _ = writeln!(out, "vfov = {}", real(vfov));
        }
        Projection::Orthographic { height } => {
            let _ = writeln!(out, "projection = \"orthographic\"");
            let _ = writeln!(out, "height = {}", real(height));
        }
    }
    if c.aperture > 0.0 {
        let _ = writeln!(out, "aperture = {}", real(c.aperture));
        let _ = writeln!(out, "focus_distance = {}", real(c.focus_distance));
    }
    let r = &scene.render;
    let _ = writeln!(out, "\n[render]");
    let _ = writeln!(out, "width = {}", r.width);
    let _ = writeln!(out, "height = {}", r.height);
    let _ = writeln!(out, "spp = {}", r.spp);
    let _ = writeln!(out, "max_bounces = {}", r.max_bounces);
    let _ = writeln!(out, "seed = {}", r.seed);
    let _ = writeln!(out, "light_sampling = {}", r.light_sampling);
    let _ = writeln!(out, "russian_roulette = {}", r.russian_roulette);
    let _ = writeln!(out, "sampler = {}", string(r.sampler.name()));
    let _ = writeln!(out, "light_sampler = {}", string(r.light_sampler.name()));
    let _ = writeln!(out, "integrator = {}", string(r.integrator.name()));

    let _ = writeln!(out, "\n[environment]");
    match &model.environment {
        EnvironmentSource::Studio => {
            let _ = writeln!(out, "preset = {}", string(studio::PRESET));
        }
        EnvironmentSource::File(path) => {
            let _ = writeln!(out, "file = {}", string(&path.to_string_lossy()));
        }
    }
    let _ = writeln!(out, "strength = {}", real(model.environment_strength));
    let _ = writeln!(out, "rotate = {}", real(model.environment_rotate));

    if model.default_material {
        let _ = writeln!(out, "\n[materials.{DEFAULT_MATERIAL}]");
        let _ = writeln!(out, "type = \"diffuse\"");
        let _ = writeln!(out, "color = {}", triple(Vec3::splat(DEFAULT_COLOR)));
    }
    let _ = writeln!(out, "\n[[meshes]]");
    let _ = writeln!(out, "file = {}", string(file));
    if model.default_material {
        let _ = writeln!(out, "material = {}", string(DEFAULT_MATERIAL));
    }
    let _ = writeln!(out, "lights = false");
    for light in &scene.lights {
        out += &light_toml(light);
    }
    out
}

fn light_toml(light: &Light) -> String {
    let mut out = String::from("\n[[lights]]\n");
    let kind = match &light.kind {
        LightKind::Point { position, radius } => {
            let mut s = format!("type = \"point\"\nposition = {}\n", triple(*position));
            if *radius > 0.0 {
                s += &format!("radius = {}\n", real(*radius));
            }
            s
        }
        LightKind::Spot {
            position,
            direction,
            inner_angle,
            outer_angle,
        } => format!(
            "type = \"spot\"\nposition = {}\ndirection = {}\ninner_angle = {}\nouter_angle = {}\n",
            triple(*position),
            triple(*direction),
            real(*inner_angle),
            real(*outer_angle)
        ),
        LightKind::Directional { direction, angle } => {
            let mut s = format!(
                "type = \"directional\"\ndirection = {}\n",
                triple(*direction)
            );
            if *angle > 0.0 {
                s += &format!("angle = {}\n", real(*angle));
            }
            s
        }
    };
    out += &kind;
    out += &format!(
        "color = {}\nintensity = {}\n",
        triple(light.color),
        real(light.intensity)
    );
    out
}
