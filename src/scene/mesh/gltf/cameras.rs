//! A glTF file's cameras: the views its nodes place. A glTF camera looks down its node's
//! local −z axis with +y up; a perspective camera gives its vertical field of view (`yfov`,
//! radians) and may give an aspect ratio (width / height). `znear` and `zfar` do not apply to
//! a path tracer and are ignored.

use super::document::{exists, read_document};
use super::nodes::placed_nodes;
use crate::scene::limits::{MAX_COORDINATE, MIN_SINE};
use glam::Vec3;
use gltf::json;
use json::camera::Type;
use json::validation::Checked;
use std::path::Path;

/// A perspective camera as the file places it.
#[derive(Clone, Debug, PartialEq)]
pub struct FileCamera {
    /// The node that places it, and its index in the file's `cameras`.
    pub node: usize,
    pub camera: usize,
    pub eye: Vec3,
    /// Unit view direction (the node's −z axis).
    pub forward: Vec3,
    /// The node's +y axis, unit.
    pub up: Vec3,
    /// Vertical field of view, degrees, in (0, 180).
    pub vfov: f32,
    /// `aspectRatio` (width / height), where the file gives one.
    pub aspect: Option<f32>,
}

impl FileCamera {
    /// A point straight ahead to aim at: far enough from the eye that `target − eye` keeps the
    /// direction's precision in f32 wherever the eye is.
    pub fn target(&self) -> Vec3 {
        self.eye + self.forward * self.eye.length().max(1.0)
    }
}

/// A camera a node places, before its kind is looked at.
struct Placed {
    node: usize,
    camera: usize,
    transform: glam::Mat4,
}

/// Camera `index` of the file (the `index`-th node, in node order, of the default scene that
/// places a camera) or, without an index, its first perspective camera; `None` where the file
/// has no perspective camera and no index was asked for. The error is a sentence naming the
/// element (`cameras[1]`), for the caller to put after the file's name.
pub fn gltf_camera(path: &Path, index: Option<usize>) -> Result<Option<FileCamera>, String> {
    let (root, _) = read_document(path)?;
    let mut placed = Vec::new();
    for p in placed_nodes(&root)? {
        if let Some(c) = root.nodes[p.node].camera {
            let camera = exists(c.value(), root.cameras.len(), "camera")
                .map_err(|e| format!("nodes[{}].camera: {e}", p.node))?;
            placed.push(Placed {
                node: p.node,
                camera,
                transform: p.transform,
            });
        }
    }
    placed.sort_by_key(|p| p.node);
    match index {
        Some(i) => {
            let Some(p) = placed.get(i) else {
                return Err(no_such_camera(i, placed.len()));
            };
            if !is_perspective(&root.cameras[p.camera]) {
                return Err(format!(
                    "camera {i} (cameras[{}], placed by nodes[{}]) is orthographic; glint renders \
                     perspective cameras only",
                    p.camera, p.node
                ));
            }
            view(&root, p).map(Some)
        }
        None => placed
            .iter()
            .find(|p| is_perspective(&root.cameras[p.camera]))
            .map(|p| view(&root, p))
            .transpose(),
    }
}

/// "the file has 2 cameras (0 and 1)": the message for an index out of range.
pub fn no_such_camera(index: usize, count: usize) -> String {
    let which = match count {
        0 => "no cameras".to_string(),
        1 => "1 camera (0)".to_string(),
        2 => "2 cameras (0 and 1)".to_string(),
        n => format!("{n} cameras (0 to {})", n - 1),
    };
    format!("there is no camera {index}: the file has {which}")
}

fn is_perspective(c: &json::Camera) -> bool {
    matches!(c.type_, Checked::Valid(Type::Perspective))
}

/// A placed perspective camera's view, checked.
fn view(root: &json::Root, p: &Placed) -> Result<FileCamera, String> {
    let field = format!("cameras[{}]", p.camera);
    let perspective = root.cameras[p.camera]
        .perspective
        .as_ref()
        .ok_or_else(|| format!("{field}: a perspective camera needs a \"perspective\" object"))?;
    let yfov = perspective.yfov;
    let vfov = yfov.to_degrees();
    if !(vfov > 0.0 && vfov < 180.0) {
        return Err(format!(
            "{field}.perspective.yfov: must be in (0, π) radians, got {yfov}"
        ));
    }
    let aspect = match perspective.aspect_ratio {
        Some(a) if !(a.is_finite() && a > 0.0) => {
            return Err(format!(
                "{field}.perspective.aspectRatio: must be a finite number > 0, got {a}"
            ));
        }
        a => a,
    };
    let eye = p.transform.transform_point3(Vec3::ZERO);
    if !eye.is_finite() || eye.abs().max_element() > MAX_COORDINATE {
        return Err(format!(
            "nodes[{}]: the camera's position {eye} is outside ±{MAX_COORDINATE:e} (the \
             numeric range glint supports)",
            p.node
        ));
    }
    let forward = p.transform.transform_vector3(Vec3::NEG_Z).as_dvec3();
    let up = p.transform.transform_vector3(Vec3::Y).as_dvec3();
    if forward.length() == 0.0 || up.length() == 0.0 {
        return Err(format!(
            "nodes[{}]: the camera's transform is degenerate (a zero scale): it has no view \
             direction (the node's −z axis) or no up (+y)",
            p.node
        ));
    }
    let (forward, up) = (forward.normalize(), up.normalize());
    if forward.cross(up).length() <= MIN_SINE {
        return Err(format!(
            "nodes[{}]: the camera's transform is degenerate: its up axis (+y) is parallel to \
             its view direction (−z)",
            p.node
        ));
    }
    Ok(FileCamera {
        node: p.node,
        camera: p.camera,
        eye,
        forward: forward.as_vec3(),
        up: up.as_vec3(),
        vfov,
        aspect,
    })
}
