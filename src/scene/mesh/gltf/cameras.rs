//! A glTF file's cameras: the views its nodes place. A glTF camera looks down its node's
//! local −z axis with +y up; a perspective camera gives its vertical field of view (`yfov`,
//! radians) and may give an aspect ratio (width / height). An orthographic camera gives its
//! view's half-width and half-height (`xmag`, `ymag`, in the node's units): its view is 2·ymag
//! high (the scene file's `height`), and xmag / ymag is its aspect ratio, which plays the part
//! of a perspective camera's `aspectRatio`: it sets a model scene's image shape, and a scene
//! file's `[render]` size overrides it, the width following the image's aspect (so xmag is met
//! exactly where the image's shape is xmag / ymag). `znear` and `zfar` do not apply to a path
//! tracer and are ignored: rays start on the plane through the node's origin (an orthographic
//! camera's) or at its origin (a perspective one's), and go on without end.

use super::document::{exists, read_document};
use super::nodes::placed_nodes;
use crate::scene::limits::{MAX_COORDINATE, MIN_LENGTH, MIN_SINE};
use crate::scene::Projection;
use glam::Vec3;
use gltf::json;
use json::camera::Type;
use json::validation::Checked;
use std::path::Path;

/// A camera as the file places it.
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
    /// The vertical field of view in degrees (`yfov`), or the orthographic view's height
    /// (2·`ymag`).
    pub projection: Projection,
    /// Width / height: a perspective camera's `aspectRatio`, where the file gives one; an
    /// orthographic camera's `xmag / ymag`.
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
/// places a camera) or, without an index, its first one; `None` where the file has no camera
/// and no index was asked for. The error is a sentence naming the element (`cameras[1]`), for
/// the caller to put after the file's name.
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
            view(&root, p).map(Some)
        }
        None => placed.first().map(|p| view(&root, p)).transpose(),
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

/// A camera's projection and aspect ratio (width / height, where it has one), checked.
fn projection(camera: &json::Camera, field: &str) -> Result<(Projection, Option<f32>), String> {
    match camera.type_ {
        Checked::Valid(Type::Perspective) => {
            let perspective = camera.perspective.as_ref().ok_or_else(|| {
                format!("{field}: a perspective camera needs a \"perspective\" object")
            })?;
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
            Ok((Projection::Perspective { vfov }, aspect))
        }
        Checked::Valid(Type::Orthographic) => {
            let orthographic = camera.orthographic.as_ref().ok_or_else(|| {
                format!("{field}: an orthographic camera needs an \"orthographic\" object")
            })?;
            // glTF asks for non-zero magnifications and advises against negative ones (they
            // would mirror the image); glint takes positive ones only, within the range of
            // lengths the scene file's `height` takes (2·ymag is the view's height).
            let magnification = |name: &str, value: f32| {
                let half = if name == "xmag" { "width" } else { "height" };
                if !(value.is_finite() && value > 0.0) {
                    return Err(format!(
                        "{field}.orthographic.{name}: must be a finite number > 0 (the view's \
                         half-{half}), got {value}"
                    ));
                }
                let (min, max) = (0.5 * MIN_LENGTH, 0.5 * MAX_COORDINATE);
                if !(min..=max).contains(&value) {
                    return Err(format!(
                        "{field}.orthographic.{name}: must be in [{min:e}, {max:e}] (the \
                         numeric range glint supports), got {value:e}"
                    ));
                }
                Ok(value)
            };
            let xmag = magnification("xmag", orthographic.xmag)?;
            let ymag = magnification("ymag", orthographic.ymag)?;
            let aspect = xmag / ymag;
            Ok((
                Projection::Orthographic { height: 2.0 * ymag },
                Some(aspect),
            ))
        }
        Checked::Invalid => Err(format!(
            "{field}.type: must be \"perspective\" or \"orthographic\""
        )),
    }
}

/// A placed camera's view, checked.
fn view(root: &json::Root, p: &Placed) -> Result<FileCamera, String> {
    let field = format!("cameras[{}]", p.camera);
    let (projection, aspect) = projection(&root.cameras[p.camera], &field)?;
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
        projection,
        aspect,
    })
}
