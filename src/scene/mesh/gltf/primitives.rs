//! Meshes' primitives: each checked against its accessors before any is read (a plan), then
//! decoded into a mesh part's geometry.

use super::accessor::{component_name, type_name, Decoder, Layout};
use super::document::{exists, Buffers};
use crate::scene::mesh::Geometry;
use glam::{Vec2, Vec3, Vec4};
use gltf::json;
use json::accessor::{ComponentType, Type};
use json::mesh::{Mode, Semantic};
use json::validation::Checked;

/// A primitive, checked, with the accessors to read.
pub(super) struct PrimitivePlan {
    /// `meshes[m].primitives[p]`, for messages.
    pub(super) name: String,
    pub(super) positions: usize,
    pub(super) normals: Option<usize>,
    pub(super) uvs: Option<usize>,
    /// TEXCOORD_1.
    pub(super) uvs1: Option<usize>,
    pub(super) tangents: Option<usize>,
    /// COLOR_0, and whether it is a VEC4 (RGBA) rather than a VEC3 (RGB).
    pub(super) colors: Option<(usize, bool)>,
    pub(super) indices: Option<usize>,
    pub(super) material: Option<usize>,
    pub(super) triangles: u64,
}

/// Checks mesh `m`'s primitives and their accessors against the buffers, reading nothing.
pub(super) fn mesh_plan(
    root: &json::Root,
    buffers: &Buffers,
    m: usize,
) -> Result<Vec<PrimitivePlan>, String> {
    let mut plans = Vec::new();
    for (p, primitive) in root.meshes[m].primitives.iter().enumerate() {
        let name = format!("meshes[{m}].primitives[{p}]");
        match primitive.mode {
            Checked::Valid(Mode::Triangles) => {}
            Checked::Valid(other) => {
                return Err(format!(
                    "{name}: mode {other:?} is not supported; only triangle lists are"
                ))
            }
            Checked::Invalid => return Err(format!("{name}.mode: not a glTF primitive mode")),
        }
        let attribute = |semantic: Semantic, label: &str, kind: Type| {
            primitive
                .attributes
                .get(&Checked::Valid(semantic))
                .map(|a| {
                    let field = format!("{name}.attributes.{label}");
                    let a = exists(a.value(), root.accessors.len(), "accessor")
                        .map_err(|e| format!("{field}: {e}"))?;
                    let layout = Layout::of(root, buffers, a, kind, false)?;
                    Ok::<_, String>((a, layout.count))
                })
                .transpose()
        };
        let (positions, vertices) = attribute(Semantic::Positions, "POSITION", Type::Vec3)?
            .ok_or_else(|| format!("{name}.attributes: no POSITION"))?;
        let normals = attribute(Semantic::Normals, "NORMAL", Type::Vec3)?;
        let uvs = attribute(Semantic::TexCoords(0), "TEXCOORD_0", Type::Vec2)?;
        let uvs1 = attribute(Semantic::TexCoords(1), "TEXCOORD_1", Type::Vec2)?;
        let tangents = attribute(Semantic::Tangents, "TANGENT", Type::Vec4)?;
        let colors = match primitive
            .attributes
            .get(&Checked::Valid(Semantic::Colors(0)))
        {
            Some(a) => {
                let field = format!("{name}.attributes.COLOR_0");
                let a = exists(a.value(), root.accessors.len(), "accessor")
                    .map_err(|e| format!("{field}: {e}"))?;
                let rgba = color_accessor(root, a).map_err(|e| format!("{field}: {e}"))?;
                let kind = if rgba { Type::Vec4 } else { Type::Vec3 };
                let layout = Layout::of(root, buffers, a, kind, false)?;
                Some(((a, rgba), layout.count))
            }
            None => None,
        };
        for (label, other) in [
            ("NORMAL", normals),
            ("TEXCOORD_0", uvs),
            ("TEXCOORD_1", uvs1),
            ("TANGENT", tangents),
            ("COLOR_0", colors.map(|((a, _), count)| (a, count))),
        ] {
            if let Some((a, count)) = other {
                if count != vertices {
                    return Err(format!(
                        "{name}.attributes.{label}: accessors[{a}] has {count} elements, but \
                         POSITION (accessors[{positions}]) has {vertices}"
                    ));
                }
            }
        }
        let indices = match primitive.indices {
            Some(i) => {
                let i = exists(i.value(), root.accessors.len(), "accessor")
                    .map_err(|e| format!("{name}.indices: {e}"))?;
                Some((i, Layout::of(root, buffers, i, Type::Scalar, true)?.count))
            }
            None => None,
        };
        let material = match primitive.material {
            Some(i) => Some(
                exists(i.value(), root.materials.len(), "material")
                    .map_err(|e| format!("{name}.material: {e}"))?,
            ),
            None => None,
        };
        plans.push(PrimitivePlan {
            name,
            positions,
            normals: normals.map(|(a, _)| a),
            uvs: uvs.map(|(a, _)| a),
            uvs1: uvs1.map(|(a, _)| a),
            tangents: tangents.map(|(a, _)| a),
            colors: colors.map(|(a, _)| a),
            indices: indices.map(|(a, _)| a),
            material,
            triangles: indices.map_or(vertices, |(_, count)| count) as u64 / 3,
        });
    }
    Ok(plans)
}

/// Whether COLOR_0's accessor `a` is RGBA (VEC4) rather than RGB (VEC3), after checking it is
/// one of the forms glTF allows: VEC3 or VEC4 of FLOAT, or of normalized UNSIGNED_BYTE or
/// UNSIGNED_SHORT.
fn color_accessor(root: &json::Root, a: usize) -> Result<bool, String> {
    let accessor = &root.accessors[a];
    let field = format!("accessors[{a}]");
    let rgba = match accessor.type_ {
        Checked::Valid(Type::Vec3) => false,
        Checked::Valid(Type::Vec4) => true,
        Checked::Valid(other) => {
            return Err(format!(
                "{field}: type {}, but COLOR_0 must be VEC3 or VEC4",
                type_name(other)
            ))
        }
        Checked::Invalid => return Err(format!("{field}.type: not a glTF accessor type")),
    };
    match accessor.component_type {
        Checked::Valid(json::accessor::GenericComponentType(ComponentType::F32)) => {}
        Checked::Valid(json::accessor::GenericComponentType(
            c @ (ComponentType::U8 | ComponentType::U16),
        )) => {
            if !accessor.normalized {
                return Err(format!(
                    "{field}: componentType {} without \"normalized\": true; COLOR_0 must be \
                     FLOAT or normalized UNSIGNED_BYTE or UNSIGNED_SHORT",
                    component_name(c)
                ));
            }
        }
        Checked::Valid(json::accessor::GenericComponentType(c)) => {
            return Err(format!(
                "{field}: componentType {}; COLOR_0 must be FLOAT or normalized UNSIGNED_BYTE or \
                 UNSIGNED_SHORT",
                component_name(c)
            ))
        }
        Checked::Invalid => {
            return Err(format!("{field}.componentType: not a glTF component type"))
        }
    }
    Ok(rgba)
}

impl Decoder<'_> {
    pub(super) fn geometry(&mut self, plan: &PrimitivePlan) -> Result<Geometry, String> {
        let positions = self
            .layout(plan.positions, Type::Vec3, false)?
            .floats::<3>()?
            .into_iter()
            .map(Vec3::from)
            .collect::<Vec<_>>();
        let normals = match plan.normals {
            Some(a) => self
                .layout(a, Type::Vec3, false)?
                .floats::<3>()?
                .into_iter()
                .map(Vec3::from)
                .collect(),
            None => Vec::new(),
        };
        // glTF's texture coordinates have v down (the image's top row at v = 0).
        let mut uvs = |accessor: Option<usize>| -> Result<Vec<Vec2>, String> {
            Ok(match accessor {
                Some(a) => self
                    .layout(a, Type::Vec2, false)?
                    .floats::<2>()?
                    .into_iter()
                    .map(|[u, v]| Vec2::new(u, 1.0 - v))
                    .collect(),
                None => Vec::new(),
            })
        };
        let (uvs, uvs1) = (uvs(plan.uvs)?, uvs(plan.uvs1)?);
        // glTF's tangents point along increasing u, and their w (±1) makes the bitangent
        // w · normal × tangent point along increasing v of glTF's v-up normal-map convention,
        // which is glint's v: both are kept as they are.
        let tangents = match plan.tangents {
            Some(a) => self
                .layout(a, Type::Vec4, false)?
                .floats::<4>()?
                .into_iter()
                .map(Vec4::from)
                .collect(),
            None => Vec::new(),
        };
        // Linear RGB(A) multiplying the base colour: a VEC3's alpha is 1. Floats outside
        // [0, 1] (or not finite) would make a surface reflect more light than reaches it.
        let colors = match plan.colors {
            Some((a, rgba)) => {
                let colors: Vec<Vec4> = if rgba {
                    self.layout(a, Type::Vec4, false)?
                        .floats::<4>()?
                        .into_iter()
                        .map(Vec4::from)
                        .collect()
                } else {
                    self.layout(a, Type::Vec3, false)?
                        .floats::<3>()?
                        .into_iter()
                        .map(|c| Vec3::from(c).extend(1.0))
                        .collect()
                };
                if let Some((i, c)) = colors
                    .iter()
                    .enumerate()
                    .find(|(_, c)| !(c.cmpge(Vec4::ZERO).all() && c.cmple(Vec4::ONE).all()))
                {
                    return Err(format!(
                        "{}.attributes.COLOR_0: accessors[{a}] element {i} is {c}, outside [0, 1]",
                        plan.name
                    ));
                }
                colors
            }
            None => Vec::new(),
        };
        let flat: Vec<u32> = match plan.indices {
            Some(a) => self.layout(a, Type::Scalar, true)?.indices()?,
            None => (0..positions.len() as u32).collect(),
        };
        Ok(Geometry {
            positions,
            normals,
            uvs,
            uvs1,
            tangents,
            colors,
            indices: flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        })
    }
}
