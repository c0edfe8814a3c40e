//! Placing a file's parts in the scene: the `[[meshes]]` transform, the triangles copied at
//! every placement, and the units stored once ([`reuse`](super::reuse) says which is which),
//! with the limits on how many triangles either may make.

use super::prepare::PreparedPart;
use super::reuse::{Plan, StoredOnce};
use super::{part_prefix, tangents, MeshFile, MeshPart, MAX_PLACED_TRIANGLES, MAX_TRIANGLES};
use crate::scene::{InstancedMesh, Triangle};
use glam::{Mat3, Mat4, Vec3};
use std::collections::HashSet;
use std::rc::Rc;

/// Triangle `t` moved by `matrix`: its vertices, its normals through the inverse transpose of
/// the linear part (renormalised), its tangents through the linear part, as
/// [`load_placed`](super::load_placed) places a file's triangles.
pub fn placed(t: &Triangle, matrix: &Mat4) -> Triangle {
    let linear = Mat3::from_mat4(*matrix);
    let normal_matrix = linear.inverse().transpose();
    Triangle {
        vertices: t.vertices.map(|v| matrix.transform_point3(v)),
        normals: t
            .normals
            .map(|n| n.map(|n| (normal_matrix * n).normalize_or_zero())),
        tangents: t
            .tangents
            .map(|c| c.map(|tangent| tangents::placed_tangent(&linear, tangent))),
        ..t.clone()
    }
}

/// Where a mesh goes in the scene: scale, then rotate about x, y, z (degrees), then translate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshTransform {
    pub scale: Vec3,
    pub rotate_degrees: Vec3,
    pub translate: Vec3,
}

impl MeshTransform {
    /// The matrix that does all three, in that order.
    pub fn matrix(&self) -> Mat4 {
        let r = self.rotate_degrees * (std::f32::consts::PI / 180.0);
        Mat4::from_translation(self.translate)
            * Mat4::from_rotation_z(r.z)
            * Mat4::from_rotation_y(r.y)
            * Mat4::from_rotation_x(r.x)
            * Mat4::from_scale(self.scale)
    }
}

/// An error unless the triangles `plan` copies, placed `placements` times, stay within
/// [`MAX_PLACED_TRIANGLES`]. Copies are counted before any is made: many placements of a large
/// file would otherwise fill the memory before the count is seen.
pub(super) fn check_copy_count(
    file: &MeshFile,
    plan: &Plan,
    placements: usize,
    shown: &str,
) -> Result<(), String> {
    let faces: usize = file
        .parts
        .iter()
        .zip(&plan.copied)
        .filter(|(_, copied)| **copied)
        .map(|(p, _)| p.geometry.indices.len())
        .sum();
    let copies = faces.saturating_mul(placements);
    // The copied geometry's own triangles, each geometry once: more than those are copies.
    let mut seen = HashSet::new();
    let copied_once: usize = file
        .parts
        .iter()
        .zip(&plan.copied)
        .filter(|(p, copied)| **copied && seen.insert(Rc::as_ptr(&p.geometry)))
        .map(|(p, _)| p.geometry.indices.len())
        .sum();
    if copies > MAX_PLACED_TRIANGLES && copies > copied_once {
        return Err(format!(
            "{shown}: {faces} triangles to copy (a mesh the file reuses counted at each use) \
             placed {} time{} are {copies} triangles, more than the {MAX_PLACED_TRIANGLES} one \
             mesh entry may copy; triangles are copied when their material emits light, is \
             alpha-tested or blended, or has a normal map (the two-level structure holds none \
             of those)",
            placements,
            if placements == 1 { "" } else { "s" }
        ));
    }
    Ok(())
}

/// Places a file's prepared parts, counting the triangles skipped for zero area.
pub(super) struct Placer<'a> {
    pub(super) file: &'a MeshFile,
    pub(super) prepared: &'a [PreparedPart],
    /// The mesh file as messages show it.
    pub(super) shown: &'a str,
    /// Triangles of zero area once placed, skipped so far.
    pub(super) degenerate: usize,
}

impl Placer<'_> {
    /// The copied parts' triangles in the scene's coordinates: placement after placement, each
    /// with every copied part in the file's order (one placement is exactly the mesh without
    /// instances).
    pub(super) fn copies(
        &mut self,
        placements: &[Mat4],
        copied: &[bool],
    ) -> Result<Vec<Triangle>, String> {
        let mut triangles = Vec::new();
        for scene_matrix in placements {
            for (p, part) in self
                .file
                .parts
                .iter()
                .enumerate()
                .filter(|(p, _)| copied[*p])
            {
                self.place(p, *scene_matrix * part.transform, &mut triangles)?;
                if triangles.len() > MAX_TRIANGLES {
                    return Err(self.too_many());
                }
            }
        }
        Ok(triangles)
    }

    /// The units stored once, each with its triangles in its own coordinates; `copies` is how
    /// many triangles were copied, which count towards [`MAX_TRIANGLES`] too.
    pub(super) fn stored_once(
        &mut self,
        units: Vec<StoredOnce>,
        copies: usize,
    ) -> Result<Vec<InstancedMesh>, String> {
        let mut instanced = Vec::new();
        let mut stored = 0usize;
        for unit in units {
            let mut own = Vec::new();
            for (p, matrix) in unit.members {
                self.place(p, matrix, &mut own)?;
            }
            stored += own.len();
            if copies + stored > MAX_TRIANGLES {
                return Err(self.too_many());
            }
            if !own.is_empty() {
                instanced.push(InstancedMesh {
                    triangles: own,
                    placements: unit.placements,
                });
            }
        }
        Ok(instanced)
    }

    /// Part `p`'s triangles moved by `matrix`, added to `out`.
    fn place(&mut self, p: usize, matrix: Mat4, out: &mut Vec<Triangle>) -> Result<(), String> {
        let part = &self.file.parts[p];
        place_part(part, &self.prepared[p], matrix, out, &mut self.degenerate)
            .map_err(|f| not_finite(self.shown, part, f))
    }

    fn too_many(&self) -> String {
        format!(
            "{}: more than {MAX_TRIANGLES} triangles; glint holds at most that many",
            self.shown
        )
    }
}

/// Adds `part`'s triangles, moved by `matrix`, to `out`; those of zero area after the move
/// are skipped and counted in `degenerate`. A triangle that is not finite after the move is an
/// error: its index.
fn place_part(
    part: &MeshPart,
    prepared: &PreparedPart,
    matrix: Mat4,
    out: &mut Vec<Triangle>,
    degenerate: &mut usize,
) -> Result<(), usize> {
    let geometry = &*part.geometry;
    let count = geometry.positions.len();
    // Normals go through the inverse transpose of the linear part.
    let normal_matrix = Mat3::from_mat4(matrix).inverse().transpose();
    let linear = Mat3::from_mat4(matrix);
    for (f, idx) in geometry.indices.iter().enumerate() {
        let v = idx.map(|i| matrix.transform_point3(geometry.positions[i as usize]));
        let cross = (v[1] - v[0]).cross(v[2] - v[0]);
        let area2 = cross.length();
        if area2.is_nan() || area2 <= 0.0 || !area2.is_finite() {
            if !v.iter().all(|p| p.is_finite()) {
                return Err(f);
            }
            *degenerate += 1;
            continue;
        }
        let normals = prepared
            .use_normals
            .then(|| {
                idx.map(|i| (normal_matrix * geometry.normals[i as usize]).normalize_or_zero())
            })
            // A zero vertex normal cannot shade: the triangle is shaded flat.
            .filter(|n| n.iter().all(|n| *n != Vec3::ZERO));
        let uvs = (geometry.uvs.len() == count).then(|| idx.map(|i| geometry.uvs[i as usize]));
        let uvs1 = (geometry.uvs1.len() == count).then(|| idx.map(|i| geometry.uvs1[i as usize]));
        let colors =
            (geometry.colors.len() == count).then(|| idx.map(|i| geometry.colors[i as usize]));
        let tangents = prepared
            .corners
            .as_ref()
            .and_then(|c| c.get(f))
            .map(|c| c.map(|t| tangents::placed_tangent(&linear, t)));
        out.push(Triangle {
            vertices: v,
            normals,
            material: prepared.material,
            uvs,
            uvs1,
            tangents,
            colors,
        });
    }
    Ok(())
}

/// The error for face `face` of `part`, not finite once placed.
fn not_finite(shown: &str, part: &MeshPart, face: usize) -> String {
    format!(
        "{shown}: {}face {face} is not finite after the transform",
        part_prefix(&part.name)
    )
}
