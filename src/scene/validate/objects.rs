//! `[[spheres]]`, `[[quads]]` and `[[meshes]]`: the scene's geometry.

use super::super::file::{MeshToml, QuadToml, ScaleToml, SphereToml, Triple, VolumeToml, S};
use super::super::light::Light;
use super::super::limits::{MIN_LENGTH, MIN_SINE};
use super::super::mesh::{self, MeshTransform};
use super::super::{
    Alpha, AlphaMode, InstancedMesh, Material, MaterialKind, Quad, Sphere, Triangle,
};
use super::fields::{coordinates, fail, length_in_range, real, sine_between, vec3, FieldError};
use super::materials::Materials;
use super::media::MediaNames;
use glam::{Mat4, Vec3};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

/// The scene's geometry, and warnings to print (from mesh files).
pub(super) struct Objects {
    pub(super) spheres: Vec<Sphere>,
    pub(super) quads: Vec<Quad>,
    pub(super) triangles: Vec<Triangle>,
    /// Meshes placed many times and stored once (see `Material::two_level`).
    pub(super) instanced: Vec<InstancedMesh>,
    /// The punctual lights of glTF files (`[[meshes]] lights`, default true).
    pub(super) lights: Vec<Light>,
    pub(super) warnings: Vec<String>,
    /// (material, medium): the materials made for objects that bound a medium.
    pub(super) boundaries: Vec<(u32, u32)>,
}

/// Objects that bound a medium get a copy of their material for it (the kernel finds the
/// medium inside an object from the material it hits): one per (material, medium) pair.
struct Boundaries<'a> {
    media: &'a MediaNames,
    made: BTreeMap<(u32, u32), u32>,
}

impl Boundaries<'_> {
    /// The material for objects of `material` filled with `medium`.
    fn material(&mut self, material: u32, medium: u32, materials: &mut Materials) -> u32 {
        *self.made.entry((material, medium)).or_insert_with(|| {
            let mut copy = materials.list[material as usize].clone();
            copy.name = format!(
                "{} (medium {})",
                copy.name, self.media.list[medium as usize].name
            );
            materials.list.push(copy);
            materials.list.len() as u32 - 1
        })
    }
}

/// One warning per material that is alpha-tested or blended but used by spheres or quads,
/// which are always opaque (src/cpu/geometry/alpha.rs): alpha applies to meshes only.
fn opaque_only_warnings(spheres: &[Sphere], quads: &[Quad], materials: &[Material]) -> Vec<String> {
    let used = spheres
        .iter()
        .map(|s| s.material)
        .chain(quads.iter().map(|q| q.material))
        .collect::<std::collections::BTreeSet<_>>();
    used.into_iter()
        .map(|m| &materials[m as usize])
        .filter(|m| m.alpha.mode != AlphaMode::Opaque)
        .map(|m| {
            format!(
                "materials.{}: its alpha_mode applies to meshes only; spheres and quads that use \
                 it are opaque",
                m.name
            )
        })
        .collect()
}

/// The scene's spheres, quads and meshes (read relative to `folder`; their own materials are
/// added to `materials`), each list checked in the order of the file.
pub(super) fn validate_objects(
    spheres_toml: &[S<SphereToml>],
    quads_toml: &[S<QuadToml>],
    meshes_toml: &[S<MeshToml>],
    folder: &Path,
    materials: &mut Materials,
    media: &MediaNames,
    subsurface: &BTreeMap<u32, u32>,
) -> Result<Objects, FieldError> {
    let mut boundaries = Boundaries {
        media,
        made: BTreeMap::new(),
    };
    let mut spheres = Vec::with_capacity(spheres_toml.len());
    for (i, s) in spheres_toml.iter().enumerate() {
        let mut sphere = validate_sphere(s.get_ref(), i, materials)?;
        // An explicit medium, else the one a subsurface material implies.
        let medium = match &s.get_ref().medium {
            Some(m) => Some(media.homogeneous(m, &format!("spheres[{i}].medium"))?),
            None => subsurface.get(&sphere.material).copied(),
        };
        if let Some(medium) = medium {
            sphere.material = boundaries.material(sphere.material, medium, materials);
        }
        spheres.push(sphere);
    }
    let quads = quads_toml
        .iter()
        .enumerate()
        .map(|(i, q)| validate_quad(q.get_ref(), i, materials))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, (q, quad)) in quads_toml.iter().zip(&quads).enumerate() {
        if subsurface.contains_key(&quad.material) {
            return fail(
                q.get_ref().material.span(),
                format!("quads[{i}].material"),
                "a subsurface material fills its object with a medium, and a quad bounds no \
                 volume: use it on spheres and closed meshes",
            );
        }
    }
    let mut meshes = Meshes {
        triangles: Vec::new(),
        instanced: Vec::new(),
        unique_triangles: 0,
        instance_count: 0,
        lights: Vec::new(),
        warnings: opaque_only_warnings(&spheres, &quads, &materials.list),
    };
    for (i, m) in meshes_toml.iter().enumerate() {
        let medium = match (&m.get_ref().medium, &m.get_ref().material) {
            (Some(name), _) => Some((
                media.homogeneous(name, &format!("meshes[{i}].medium"))?,
                name,
                "medium",
            )),
            // A subsurface material given to the whole mesh fills it.
            (None, Some(material)) => materials
                .index(material.get_ref())
                .and_then(|index| subsurface.get(&index))
                .map(|&medium| (medium, material, "material")),
            (None, None) => None,
        };
        let (triangles, instanced) = (meshes.triangles.len(), meshes.instanced.len());
        meshes.add(m.get_ref(), i, folder, materials)?;
        if let Some((medium, name, key)) = medium {
            meshes
                .fill(triangles, instanced, medium, materials, &mut boundaries)
                .or_else(|message| fail(name.span(), format!("meshes[{i}].{key}"), message))?;
        }
    }
    Ok(Objects {
        spheres,
        quads,
        triangles: meshes.triangles,
        instanced: meshes.instanced,
        lights: meshes.lights,
        warnings: meshes.warnings,
        boundaries: boundaries
            .made
            .iter()
            .map(|(&(_, medium), &material)| (material, medium))
            .collect(),
    })
}

/// `spheres[i]`: its center, radius (> 0, within the coordinate range) and material.
fn validate_sphere(s: &SphereToml, i: usize, materials: &Materials) -> Result<Sphere, FieldError> {
    let field = |f: &str| format!("spheres[{i}].{f}");
    let center = coordinates(&s.center, &field("center"))?;
    let radius = real(&s.radius, &field("radius"))?;
    if radius <= 0.0 {
        return fail(
            s.radius.span(),
            field("radius"),
            format!("must be > 0, got {radius}"),
        );
    }
    length_in_range(&s.radius, &field("radius"), radius, MIN_LENGTH)?;
    let material = materials.reference(&s.material, field("material"))?;
    Ok(Sphere {
        center,
        radius,
        material,
    })
}

/// `quads[i]`: its corner, two edges that span a parallelogram (neither parallel nor too
/// short) and material.
fn validate_quad(q: &QuadToml, i: usize, materials: &Materials) -> Result<Quad, FieldError> {
    let field = |f: &str| format!("quads[{i}].{f}");
    let corner = coordinates(&q.corner, &field("corner"))?;
    let u = coordinates(&q.u, &field("u"))?;
    let v = coordinates(&q.v, &field("v"))?;
    // Scale-relative: the angle between the edges, not the area against a fixed bound.
    if u == Vec3::ZERO || v == Vec3::ZERO || sine_between(u, v) <= MIN_SINE {
        return fail(
            q.v.span(),
            field("v"),
            format!("degenerate quad: edges u = {u} and v = {v} are parallel or zero"),
        );
    }
    for (edge, name, span) in [(u, "u", q.u.span()), (v, "v", q.v.span())] {
        let length = edge.as_dvec3().length();
        if length < MIN_LENGTH as f64 {
            return fail(
                span,
                field(name),
                format!(
                    "the edge is {length:e} long, shorter than {MIN_LENGTH:e} (the \
                     numeric range glint supports)"
                ),
            );
        }
    }
    let material = materials.reference(&q.material, field("material"))?;
    if let Some(m) = &q.medium {
        return fail(
            m.span(),
            field("medium"),
            "a quad bounds no volume: a medium fills a sphere or a closed mesh",
        );
    }
    Ok(Quad {
        corner,
        u,
        v,
        material,
    })
}

/// The `[[meshes]]` read so far, and the counts the scene's limits apply to.
struct Meshes {
    triangles: Vec<Triangle>,
    instanced: Vec<InstancedMesh>,
    /// The triangles of `instanced`, each counted once.
    unique_triangles: usize,
    /// The placements of `instanced`, all together.
    instance_count: usize,
    lights: Vec<Light>,
    warnings: Vec<String>,
}

impl Meshes {
    /// `meshes[i]`: its transform, material and instances checked, then its file read (its
    /// materials added to `materials`), with the glTF file's lights unless `lights = false`.
    fn add(
        &mut self,
        m: &MeshToml,
        i: usize,
        folder: &Path,
        materials: &mut Materials,
    ) -> Result<(), FieldError> {
        let field = &|f: &str| format!("meshes[{i}].{f}");
        let transform = mesh_transform(m, field)?;
        let material = match &m.material {
            Some(name) => Some(materials.reference(name, field("material"))?),
            None => None,
        };
        // The mesh's own transform first, then each instance's.
        let placements: Vec<Mat4> = match &m.instances {
            None => vec![transform.matrix()],
            Some(list) => instances(list, &field("instances"))?
                .iter()
                .map(|i| i.matrix() * transform.matrix())
                .collect(),
        };
        let file = m.file.get_ref();
        // What is placed two or more times (by `instances` or by the file itself) comes back
        // stored once where its materials allow (src/scene/mesh/reuse.rs), the rest copied.
        let loaded = mesh::load_placed(
            &folder.join(file),
            file,
            &placements,
            material,
            m.smooth.unwrap_or(true),
            &mut materials.list,
            &mut materials.textures,
        )
        .or_else(|message| fail(m.file.span(), field("file"), message))?;
        self.warnings.extend(loaded.warnings);
        self.triangles.extend(loaded.triangles);
        self.add_instanced(loaded.instanced, m, field)?;
        if m.lights.unwrap_or(true) && mesh::is_gltf(Path::new(file)) {
            self.add_gltf_lights(m, &placements, folder, field)?;
        }
        if self.triangles.len() + self.unique_triangles > mesh::MAX_TRIANGLES {
            return fail(
                m.file.span(),
                field("file"),
                format!(
                    "the scene's meshes hold more than {} triangles",
                    mesh::MAX_TRIANGLES
                ),
            );
        }
        Ok(())
    }

    /// Fills the mesh just added (its triangles from `triangles` on, its instanced meshes
    /// from `instanced` on) with `medium`: each of its materials replaced by the copy that
    /// bounds it. The mesh must be closed, or inside and outside are not defined.
    fn fill(
        &mut self,
        triangles: usize,
        instanced: usize,
        medium: u32,
        materials: &mut Materials,
        boundaries: &mut Boundaries,
    ) -> Result<(), String> {
        let open = |t: &[Triangle]| open_edges(t);
        let own = open(&self.triangles[triangles..]);
        let placed = self.instanced[instanced..]
            .iter()
            .map(|m| open(&m.triangles))
            .max()
            .unwrap_or(0);
        if own + placed > 0 {
            return Err(format!(
                "the mesh is not closed ({} edges belong to an odd number of triangles): a \
                 medium fills only a closed mesh, whose inside is defined",
                own.max(placed)
            ));
        }
        for t in &mut self.triangles[triangles..] {
            t.material = boundaries.material(t.material, medium, materials);
        }
        for mesh in &mut self.instanced[instanced..] {
            for t in &mut mesh.triangles {
                t.material = boundaries.material(t.material, medium, materials);
            }
        }
        Ok(())
    }

    /// The meshes `m` placed more than once, within the scene's limit on instances.
    fn add_instanced(
        &mut self,
        instanced: Vec<InstancedMesh>,
        m: &MeshToml,
        field: &dyn Fn(&str) -> String,
    ) -> Result<(), FieldError> {
        for mesh in instanced {
            self.unique_triangles += mesh.triangles.len();
            self.instance_count += mesh.placements.len();
            if self.instance_count > mesh::MAX_INSTANCES {
                let (span, name) = match &m.instances {
                    Some(list) => (list.span(), field("instances")),
                    None => (m.file.span(), field("file")),
                };
                return fail(
                    span,
                    name,
                    format!(
                        "the scene's meshes have more than {} instances in all, more than one \
                         GPU binding of 128 MiB holds the transforms of",
                        mesh::MAX_INSTANCES
                    ),
                );
            }
            self.instanced.push(mesh);
        }
        Ok(())
    }

    /// The punctual lights of the glTF file `m` names, at each of its `placements`.
    fn add_gltf_lights(
        &mut self,
        m: &MeshToml,
        placements: &[Mat4],
        folder: &Path,
        field: &dyn Fn(&str) -> String,
    ) -> Result<(), FieldError> {
        let file = m.file.get_ref();
        for (p, placement) in placements.iter().enumerate() {
            let (mut file_lights, file_warnings) =
                mesh::gltf_lights(&folder.join(file), *placement).or_else(|message| {
                    fail(m.file.span(), field("file"), format!("{file}: {message}"))
                })?;
            // The same warnings for every placement: said once. A file without lights
            // is not read again for every instance.
            if p == 0 {
                self.warnings
                    .extend(file_warnings.into_iter().map(|w| format!("{file}: {w}")));
                if file_lights.is_empty() {
                    break;
                }
            }
            self.lights.append(&mut file_lights);
        }
        Ok(())
    }
}

/// A mesh's own `translate`, `rotate` (degrees) and `scale` (each factor > 0).
fn mesh_transform(
    m: &MeshToml,
    field: &dyn Fn(&str) -> String,
) -> Result<MeshTransform, FieldError> {
    transform(&m.translate, &m.rotate, &m.scale, field)
}

/// `translate`, `rotate` (degrees) and `scale` (each factor > 0), of a mesh or a volume.
fn transform(
    translate: &Option<S<Triple>>,
    rotate: &Option<S<Triple>>,
    scale: &Option<S<ScaleToml>>,
    field: &dyn Fn(&str) -> String,
) -> Result<MeshTransform, FieldError> {
    let m = TransformFields {
        translate,
        rotate,
        scale,
    };
    let translate = match &m.translate {
        Some(t) => coordinates(t, &field("translate"))?,
        None => Vec3::ZERO,
    };
    let rotate = match &m.rotate {
        Some(r) => vec3(r, &field("rotate"))?,
        None => Vec3::ZERO,
    };
    let scale = match &m.scale {
        None => Vec3::ONE,
        Some(s) => {
            let v = match s.get_ref() {
                ScaleToml::Uniform(r) => Vec3::splat(r.0 as f32),
                ScaleToml::PerAxis(a) => Vec3::new(a[0].0 as f32, a[1].0 as f32, a[2].0 as f32),
            };
            positive_scale(v, s.span(), &field("scale"))?
        }
    };
    Ok(MeshTransform {
        scale,
        rotate_degrees: rotate,
        translate,
    })
}

struct TransformFields<'a> {
    translate: &'a Option<S<Triple>>,
    rotate: &'a Option<S<Triple>>,
    scale: &'a Option<S<ScaleToml>>,
}

/// `[[volumes]]`: each places a grid medium. The medium is copied with the volume's placement
/// (each volume its own medium slot, as its grid lies elsewhere), and an interface box around
/// the grid's padded active box, made of 12 triangles in a material of its own, bounds it.
pub(super) fn place_volumes(
    volumes: &[S<VolumeToml>],
    objects: &mut Objects,
    materials: &mut Materials,
    media: &mut MediaNames,
) -> Result<(), FieldError> {
    for (i, v) in volumes.iter().enumerate() {
        let field = |f: &str| format!("volumes[{i}].{f}");
        let v = v.get_ref();
        let index = media.reference(&v.medium, &field("medium"))?;
        let mut medium = media.list[index as usize].clone();
        let Some(grid) = &mut medium.grid else {
            return fail(
                v.medium.span(),
                field("medium"),
                format!(
                    "medium {:?} has no density grid: a volume places a grid medium (give it \
                     grid = \"file.vdb\"); a homogeneous medium fills a sphere or a closed mesh",
                    v.medium.get_ref()
                ),
            );
        };
        grid.placement = transform(&v.translate, &v.rotate, &v.scale, &field)?.matrix();
        let corners = grid.grid.corners(&grid.placement);
        if corners
            .iter()
            .any(|c| !c.is_finite() || c.abs().max_element() > super::super::limits::MAX_COORDINATE)
        {
            return fail(
                v.medium.span(),
                field("medium"),
                "the volume's box lies beyond the coordinates glint supports: scale or move it",
            );
        }
        medium.name = format!("{} (volumes[{i}])", medium.name);
        media.list.push(medium);
        let medium = media.list.len() as u32 - 1;
        materials.list.push(Material::untextured(
            format!("volumes[{i}] (interface)"),
            MaterialKind::Dielectric { ior: 1.0 },
            Vec3::ONE,
            Vec3::ZERO,
            Alpha::OPAQUE,
        ));
        let material = materials.list.len() as u32 - 1;
        objects.triangles.extend(box_triangles(&corners, material));
        objects.boundaries.push((material, medium));
    }
    Ok(())
}

/// The 12 triangles of the box with these corners (corner c at bit 0: +x, bit 1: +y, bit 2:
/// +z), wound so that their normals point out of the box.
fn box_triangles(corners: &[Vec3; 8], material: u32) -> Vec<Triangle> {
    const FACES: [[usize; 4]; 6] = [
        [0, 1, 3, 2],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 3, 7, 5],
    ];
    let centre = corners.iter().copied().sum::<Vec3>() / 8.0;
    let mut out = Vec::with_capacity(12);
    for [a, b, c, d] in FACES {
        for [p, q, r] in [[a, b, c], [a, c, d]] {
            let mut vertices = [corners[p], corners[q], corners[r]];
            let normal = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
            let middle = (vertices[0] + vertices[1] + vertices[2]) / 3.0;
            if normal.dot(middle - centre) < 0.0 {
                vertices.swap(1, 2);
            }
            out.push(Triangle {
                vertices,
                normals: None,
                material,
                uvs: None,
                uvs1: None,
                tangents: None,
                colors: None,
            });
        }
    }
    out
}

/// A scale factor per axis, each finite and > 0 (a mesh's `scale` or an instance's).
fn positive_scale(v: Vec3, span: Range<usize>, field: &str) -> Result<Vec3, FieldError> {
    if !v.is_finite() || v.min_element() <= 0.0 {
        return fail(
            span,
            field,
            format!("degenerate transform: every scale factor must be finite and > 0, got {v}"),
        );
    }
    Ok(v)
}

/// A `[[meshes]]` entry's `instances` (named `field`): at least one, each a table of the
/// mesh's own optional `translate`, `rotate` and `scale`, with the same meanings and checks.
/// Errors name the instance and its key, at the instance's place in the file.
fn instances(list: &S<Vec<S<toml::Value>>>, field: &str) -> Result<Vec<MeshTransform>, FieldError> {
    if list.get_ref().is_empty() {
        return fail(
            list.span(),
            field,
            "must place the mesh at least once (leave `instances` out to place it as it is)",
        );
    }
    let mut out = Vec::with_capacity(list.get_ref().len());
    for (j, entry) in list.get_ref().iter().enumerate() {
        let at = |key: &str| format!("{field}[{j}]{key}");
        let toml::Value::Table(table) = entry.get_ref() else {
            return fail(
                entry.span(),
                at(""),
                format!(
                    "must be a table like {{ translate = [x, y, z], rotate = [x, y, z], scale = s }}, got a {}",
                    entry.get_ref().type_str()
                ),
            );
        };
        let mut instance = MeshTransform {
            scale: Vec3::ONE,
            rotate_degrees: Vec3::ZERO,
            translate: Vec3::ZERO,
        };
        for (key, value) in table {
            let name = at(&format!(".{key}"));
            // The values inside a table carry no place of their own: the instance's is used.
            let value = S::new(entry.span(), value.clone());
            match key.as_str() {
                "translate" => instance.translate = coordinates(&value, &name)?,
                "rotate" => instance.rotate_degrees = vec3(&value, &name)?,
                "scale" => {
                    let v = match value.get_ref() {
                        toml::Value::Float(r) => Vec3::splat(*r as f32),
                        toml::Value::Integer(r) => Vec3::splat(*r as f32),
                        _ => vec3(&value, &name)?,
                    };
                    instance.scale = positive_scale(v, entry.span(), &name)?;
                }
                _ => {
                    return fail(
                        entry.span(),
                        name,
                        "unknown key: an instance takes `translate`, `rotate` and `scale`",
                    )
                }
            }
        }
        out.push(instance);
    }
    Ok(out)
}

/// How many edges of `triangles` (vertices matched by exact position) belong to an odd number
/// of them: zero for a closed mesh, whose every edge two faces (or four, ...) share.
fn open_edges(triangles: &[Triangle]) -> usize {
    let key = |v: Vec3| v.to_array().map(f32::to_bits);
    let mut odd = std::collections::HashSet::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (key(t.vertices[k]), key(t.vertices[(k + 1) % 3]));
            let edge = if a <= b { (a, b) } else { (b, a) };
            if !odd.remove(&edge) {
                odd.insert(edge);
            }
        }
    }
    odd.len()
}
