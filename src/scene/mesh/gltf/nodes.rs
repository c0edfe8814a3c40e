//! A glTF file's node hierarchy: which nodes the default scene places, and where. Meshes
//! (`primitives.rs`), cameras (`cameras.rs`) and punctual lights (`lights.rs`) hang from
//! these nodes.

use super::document::exists;
use glam::{Mat4, Quat, Vec3};
use gltf::json;

/// A node of the default scene and its world transform (its own times its ancestors').
pub(super) struct PlacedNode {
    pub(super) node: usize,
    pub(super) transform: Mat4,
}

/// The nodes the default scene places, each with its world transform, parents before their
/// children. The hierarchy must be a set of trees, as glTF requires: a node has at most one
/// parent and is never its own ancestor, so each is visited once (a cycle would otherwise
/// never end, and a node reached by many paths could multiply its mesh without bound).
pub(super) fn placed_nodes(root: &json::Root) -> Result<Vec<PlacedNode>, String> {
    let nodes = &root.nodes;
    let n = nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (i, node) in nodes.iter().enumerate() {
        for (k, child) in node.children.iter().flatten().enumerate() {
            let c = exists(child.value(), n, "node")
                .map_err(|e| format!("nodes[{i}].children[{k}]: {e}"))?;
            if c == i {
                return Err(format!("nodes[{i}] is its own child"));
            }
            if let Some(p) = parent[c] {
                return Err(format!(
                    "nodes[{c}] is a child of both nodes[{p}] and nodes[{i}]; a glTF node has at \
                     most one parent"
                ));
            }
            parent[c] = Some(i);
        }
    }
    // With one parent at most, following parents from any node either ends at a root or
    // comes back to a node on the way: a cycle.
    const NEW: u8 = 0;
    const ON_CHAIN: u8 = 1;
    const DONE: u8 = 2;
    let mut state = vec![NEW; n];
    for start in 0..n {
        let mut chain = Vec::new();
        let mut at = Some(start);
        while let Some(i) = at {
            match state[i] {
                DONE => break,
                ON_CHAIN => {
                    // Parent to child: i, then the chain back down to i.
                    let from = chain.iter().position(|&c| c == i).unwrap_or(0);
                    let cycle: Vec<usize> = std::iter::once(i)
                        .chain(chain[from..].iter().rev().copied())
                        .collect();
                    let shown: Vec<String> = cycle
                        .iter()
                        .take(8)
                        .map(|c| format!("nodes[{c}]"))
                        .collect();
                    return Err(format!(
                        "nodes[{i}] is its own ancestor: the node hierarchy has a cycle ({}{})",
                        shown.join(" → "),
                        if cycle.len() > 8 { " → …" } else { "" }
                    ));
                }
                _ => {}
            }
            state[i] = ON_CHAIN;
            chain.push(i);
            at = parent[i];
        }
        for i in chain {
            state[i] = DONE;
        }
    }

    let s = root.scene.map_or(0, |s| s.value());
    if root.scenes.is_empty() {
        return Err("malformed glTF: no scene".to_string());
    }
    let scene =
        &root.scenes[exists(s, root.scenes.len(), "scene").map_err(|e| format!("scene: {e}"))?];
    let mut listed = vec![false; n];
    let mut stack = Vec::new();
    for (k, r) in scene.nodes.iter().enumerate() {
        let field = format!("scenes[{s}].nodes[{k}]");
        let r = exists(r.value(), n, "node").map_err(|e| format!("{field}: {e}"))?;
        if let Some(p) = parent[r] {
            return Err(format!(
                "{field}: nodes[{r}] is a child of nodes[{p}]; a scene lists only root nodes"
            ));
        }
        if std::mem::replace(&mut listed[r], true) {
            return Err(format!("{field}: nodes[{r}] is listed twice"));
        }
        stack.push((r, Mat4::IDENTITY));
    }
    let mut placed = Vec::new();
    while let Some((i, parent_transform)) = stack.pop() {
        let node = &nodes[i];
        let local = match node.matrix {
            Some(m) => Mat4::from_cols_array(&m),
            None => Mat4::from_scale_rotation_translation(
                Vec3::from(node.scale.unwrap_or([1.0; 3])),
                Quat::from_array(node.rotation.map_or([0.0, 0.0, 0.0, 1.0], |q| q.0)),
                Vec3::from(node.translation.unwrap_or([0.0; 3])),
            ),
        };
        let transform = parent_transform * local;
        if !transform.is_finite() {
            return Err(format!(
                "nodes[{i}]: its transform (with its ancestors') is not finite"
            ));
        }
        for child in node.children.iter().flatten() {
            stack.push((child.value(), transform));
        }
        placed.push(PlacedNode { node: i, transform });
    }
    Ok(placed)
}
