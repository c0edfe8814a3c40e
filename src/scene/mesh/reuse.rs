//! Which parts of a placed mesh file are stored once and placed by transforms (the two-level
//! structure: `InstancedMesh`), and which are copied into the scene's triangles.
//!
//! A geometry (a glTF primitive) that the file places two or more times, by nodes that reuse
//! its mesh or by `EXT_mesh_gpu_instancing`, is one unit: its triangles in its own
//! coordinates, placed by the `[[meshes]]` entry's placements times each use's transform. The
//! file's other parts are one unit together, placed by the entry's placements alone (a mesh
//! with `instances`). A unit placed two or more times is stored once when every material it
//! uses allows it (`Material::two_level`) and every placement can be inverted (rays are taken
//! into the unit's coordinates; a node scaled by 0 cannot be, and its copies, all of zero area,
//! are skipped as before). Two: from there on a copy saves memory, whatever the mesh's size,
//! and the rule is one a user can predict. Every other unit is copied, exactly as before.

use super::{MeshPart, MAX_INSTANCES};
use glam::Mat4;
use std::collections::HashMap;

/// Parts stored once: each part's triangles moved by its matrix into the unit's own
/// coordinates, and the unit placed in the scene by each of `placements`.
pub(super) struct StoredOnce {
    pub(super) members: Vec<(usize, Mat4)>,
    pub(super) placements: Vec<Mat4>,
}

/// How a file's parts go into the scene.
pub(super) struct Plan {
    pub(super) stored_once: Vec<StoredOnce>,
    /// Per part: whether it is copied into the scene's triangles at every placement.
    pub(super) copied: Vec<bool>,
}

/// The plan for `parts` placed by each of `placements` (the scene's matrices), where
/// `two_level[p]` says whether part `p`'s material may be stored once. More instances than
/// [`MAX_INSTANCES`] are an error, found before any matrix is made.
pub(super) fn plan(
    parts: &[MeshPart],
    placements: &[Mat4],
    two_level: &[bool],
) -> Result<Plan, String> {
    // Parts that share a geometry (and a material: a primitive has one), in the file's order.
    let mut uses: Vec<Vec<usize>> = Vec::new();
    let mut unit_of = HashMap::new();
    for (p, part) in parts.iter().enumerate() {
        let key = (std::rc::Rc::as_ptr(&part.geometry), part.material);
        let unit = *unit_of.entry(key).or_insert_with(|| {
            uses.push(Vec::new());
            uses.len() - 1
        });
        uses[unit].push(p);
    }
    let alone: Vec<usize> = uses.iter().filter(|u| u.len() == 1).map(|u| u[0]).collect();
    let reused: Vec<&Vec<usize>> = uses.iter().filter(|u| u.len() >= 2).collect();
    let allowed = |members: &[usize]| members.iter().all(|&p| two_level[p]);

    // Counted first: an entry's instances times a file's uses can be far more matrices than
    // fit in memory.
    let alone_count = if placements.len() >= 2 && !alone.is_empty() && allowed(&alone) {
        placements.len()
    } else {
        0
    };
    let instances = reused
        .iter()
        .filter(|u| allowed(u))
        .fold(alone_count, |sum, u| {
            sum.saturating_add(placements.len().saturating_mul(u.len()))
        });
    if instances > MAX_INSTANCES {
        return Err(format!(
            "its meshes stored once are placed {instances} times, more than the {MAX_INSTANCES} \
             instances a scene may have in all (one GPU binding of 128 MiB holds their \
             transforms)"
        ));
    }

    let mut copied = vec![true; parts.len()];
    let mut stored_once = Vec::new();
    let mut store = |unit: StoredOnce, members: &[usize]| {
        if unit.placements.iter().all(invertible) {
            for &p in members {
                copied[p] = false;
            }
            stored_once.push(unit);
        }
    };
    if alone_count > 0 {
        let members = alone.iter().map(|&p| (p, parts[p].transform)).collect();
        let unit = StoredOnce {
            members,
            placements: placements.to_vec(),
        };
        store(unit, &alone);
    }
    for members in reused.into_iter().filter(|u| allowed(u)) {
        // Placement after placement, each with every use in the file's order: the order in
        // which copies are made.
        let unit = StoredOnce {
            members: vec![(members[0], Mat4::IDENTITY)],
            placements: placements
                .iter()
                .flat_map(|m| members.iter().map(move |&p| *m * parts[p].transform))
                .collect(),
        };
        store(unit, members);
    }
    Ok(Plan {
        stored_once,
        copied,
    })
}

/// Whether the kernel can take rays into the coordinates `m` places (its inverse, computed in
/// f64 as src/kernel/scene/ does, is finite in f32).
fn invertible(m: &Mat4) -> bool {
    let m = m.as_dmat4();
    m.determinant() != 0.0 && m.inverse().as_mat4().is_finite()
}
