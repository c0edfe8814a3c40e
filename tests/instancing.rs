//! `[[meshes]] instances`: a mesh file placed many times. Instances are flattened into the
//! scene's triangles (src/scene/mesh/mod.rs, `load_placed`), so an instanced scene is the scene
//! with one `[[meshes]]` entry per instance: the same triangles, and the same image on both
//! devices, bit for bit. Bad instances are errors that name `meshes[i].instances[j].key`, and
//! instance counts whose copies would not fit are refused before anything is copied.

mod common;
use common::{gpu, render_cpu, render_gpu, PathAgreement, MESH_SCENE_HEADER};
use glam::{Mat4, Vec3};
use glint::scene::stress::StressMesh;
use glint::scene::{Scene, SceneError};
use std::path::Path;

/// The placements the tests use: translated, rotated, scaled uniformly and per axis, and two
/// overlapping in part.
const PLACEMENTS: [&str; 4] = [
    "translate = [-2.0, 0.0, 0.0]",
    "translate = [2.0, 0.5, 1.0], rotate = [0.0, 90.0, 0.0], scale = 1.5",
    "translate = [0.0, -1.5, 0.0], rotate = [30.0, 0.0, 45.0], scale = [1.0, 0.5, 2.0]",
    "translate = [-1.5, 0.25, 0.0]",
];

/// A scene file in `dir` next to a small stress mesh (`mesh.ply`), loaded.
fn load(dir: &Path, toml: &str) -> Result<Scene, SceneError> {
    let mesh = dir.join("mesh.ply");
    if !mesh.exists() {
        StressMesh::new(24, 12).write_ply(&mesh).unwrap();
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    Scene::load(&path)
}

/// An emitting material, for [`instanced_and_flattened`]'s `material`.
const LAMP: &str = "\n[materials.lamp]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\nemission = [1.0, 0.5, 0.25]\n";

/// The mesh placed by `instances`, and by one `[[meshes]]` entry per placement, in `material`
/// (`white`, or `lamp` with [`LAMP`] defined).
fn instanced_and_flattened(dir: &Path, material: &str) -> (Scene, Scene) {
    let header = format!("{MESH_SCENE_HEADER}{LAMP}");
    let list = PLACEMENTS.map(|p| format!("{{ {p} }}")).join(", ");
    let instanced = format!(
        "{header}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"{material}\"\ninstances = [{list}]\n"
    );
    let mut flattened = header.clone();
    for p in PLACEMENTS {
        // An inline table's keys, one per line, are the entry's own.
        let keys = p
            .replace(", rotate", "\nrotate")
            .replace(", scale", "\nscale");
        flattened +=
            &format!("\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"{material}\"\n{keys}\n");
    }
    let instanced = load(dir, &instanced).unwrap_or_else(|e| panic!("{e}"));
    let flattened = load(dir, &flattened).unwrap_or_else(|e| panic!("{e}"));
    (instanced, flattened)
}

fn lit(scene: Scene) -> glint::scene::KernelScene {
    // Under a white sky, so that every path that escapes carries light.
    let mut scene = scene;
    scene.render.background = Vec3::ONE;
    common::sized(scene, 32, 7)
}

/// The same triangles in the same order, and the same CPU image bit for bit.
#[test]
fn instances_are_the_flattened_meshes_on_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "white");
    let per_mesh = StressMesh::new(24, 12).indices.len();
    assert_eq!(instanced.triangles.len(), 4 * per_mesh);
    assert_eq!(instanced.triangles, flattened.triangles);
    let (instanced, flattened) = (lit(instanced), lit(flattened));
    assert_eq!(instanced.triangles, flattened.triangles);
    let image = render_cpu(&instanced, 2);
    // Not a blank image: the comparison would mean nothing.
    let lit_pixels = image.pixels.iter().filter(|p| p[0] > 0.0).count();
    assert!(lit_pixels > image.pixels.len() / 4, "{lit_pixels}");
    assert_eq!(image.pixels, render_cpu(&flattened, 2).pixels);
}

/// On the GPU the instanced scene renders the flattened one's image bit for bit, and traces
/// the CPU's paths (1 spp, so pixels are paths; tests/gpu_vs_cpu.rs's 99% agreement bound).
#[test]
fn instances_are_the_flattened_meshes_on_the_gpu() {
    let Some(ctx) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "white");
    let (instanced, flattened) = (lit(instanced), lit(flattened));
    let image = render_gpu(ctx, &instanced, 1);
    assert_eq!(image.pixels, render_gpu(ctx, &flattened, 1).pixels);
    let mut agreement = PathAgreement::default();
    agreement.add(&render_cpu(&instanced, 1), &image);
    agreement.check(0.99);
}

/// Emitting instances are emitters like the flattened meshes' triangles: the same emitter
/// table (each placed triangle sampled by its power), to the bit, and the same CPU image.
#[test]
fn emitting_instances_are_sampled_as_flattened_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let (instanced, flattened) = instanced_and_flattened(dir.path(), "lamp");
    let (instanced, flattened) = (
        common::sized(instanced, 24, 3),
        common::sized(flattened, 24, 3),
    );
    let per_mesh = StressMesh::new(24, 12).indices.len();
    assert_eq!(instanced.emitters.len(), 4 * per_mesh);
    // Debug prints each f32 so that it reads back to the same bits.
    assert_eq!(
        format!("{:?}", instanced.emitters),
        format!("{:?}", flattened.emitters)
    );
    assert_eq!(
        render_cpu(&instanced, 2).pixels,
        render_cpu(&flattened, 2).pixels
    );
}

/// The mesh's own transform applies first, then the instance's: scale 2 then translate by x
/// is 2p + x (the other order would give 2p + 2x).
#[test]
fn the_mesh_transform_comes_before_the_instance() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\nscale = 2.0\n\
         rotate = [0.0, 0.0, 90.0]\ninstances = [{{ translate = [1.0, 0.0, 0.0] }}, {{ scale = 3.0 }}]\n"
    );
    let scene = load(dir.path(), &text).unwrap_or_else(|e| panic!("{e}"));
    let plain = load(
        dir.path(),
        &format!("{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\n"),
    )
    .unwrap();
    let n = plain.triangles.len();
    assert_eq!(scene.triangles.len(), 2 * n);
    let mesh = Mat4::from_rotation_z(90f32.to_radians()) * Mat4::from_scale(Vec3::splat(2.0));
    let placements = [
        Mat4::from_translation(Vec3::X) * mesh,
        Mat4::from_scale(Vec3::splat(3.0)) * mesh,
    ];
    for (k, placement) in placements.iter().enumerate() {
        for (placed, original) in scene.triangles[k * n..(k + 1) * n]
            .iter()
            .zip(&plain.triangles)
        {
            for (p, q) in placed.vertices.iter().zip(original.vertices) {
                let expected = placement.transform_point3(q);
                assert!((*p - expected).abs().max_element() < 1e-5, "{p} {expected}");
            }
        }
    }
}

/// Every kind of bad instance is refused with the instance and key named, at its line.
#[test]
fn bad_instances_are_named_errors() {
    let dir = tempfile::tempdir().unwrap();
    let header_lines = MESH_SCENE_HEADER.lines().count();
    let cases: [(&str, &[&str]); 8] = [
        ("[]", &["meshes[0].instances:", "at least once"]),
        ("[1.0]", &["meshes[0].instances[0]:", "must be a table"]),
        (
            "[{}, { scale = 0.0 }]",
            &["meshes[0].instances[1].scale:", "finite and > 0"],
        ),
        (
            "[{ scale = [1.0, -1.0, 1.0] }]",
            &["meshes[0].instances[0].scale:", "finite and > 0"],
        ),
        (
            "[{ translate = [1.0, 2.0] }]",
            &["meshes[0].instances[0].translate:", "exactly three"],
        ),
        (
            "[{ rotate = [0.0, nan, 0.0] }]",
            &["meshes[0].instances[0].rotate:", "finite"],
        ),
        (
            "[{ translate = [1e9, 0.0, 0.0] }]",
            &["meshes[0].instances[0].translate:", "within"],
        ),
        (
            "[{ translate = [0.0, 0.0, 0.0], shear = 1.0 }]",
            &["meshes[0].instances[0].shear:", "unknown key"],
        ),
    ];
    for (instances, needles) in cases {
        let text = format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"mesh.ply\"\nmaterial = \"white\"\ninstances = {instances}\n"
        );
        let e = load(dir.path(), &text).expect_err(instances);
        let message = e.to_string();
        assert!(message.contains("scene.toml:"), "{message}");
        // The line of `instances` (the header, a blank line, then four lines).
        assert_eq!(e.position.map(|p| p.0), Some(header_lines + 5), "{message}");
        for needle in needles {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
}

/// 10⁴ instances of a 2·10⁵-triangle mesh (2·10⁹ triangles), and 200 of it (4·10⁷), are more
/// than one mesh's instances may place (2²⁵): the error says so, before any copy is made (the
/// first would otherwise need hundreds of GiB). 10⁴ instances of a 36-triangle mesh load,
/// every one placed.
#[test]
fn instance_counts_are_bounded_before_copying() {
    let dir = tempfile::tempdir().unwrap();
    let many = |count: usize| {
        let list = (0..count)
            .map(|i| format!("{{ translate = [{}.0, {}.0, 0.0] }}", i % 100, i / 100))
            .collect::<Vec<_>>()
            .join(", ");
        format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"big.ply\"\nmaterial = \"white\"\ninstances = [{list}]\n"
        )
    };
    let big = StressMesh::new(400, 251);
    assert_eq!(big.indices.len(), 200_000);
    big.write_ply(&dir.path().join("big.ply")).unwrap();
    for count in [10_000, 200] {
        let e = load(dir.path(), &many(count)).expect_err("too many triangles");
        let message = e.to_string();
        let placed = format!("placed {count} times");
        for needle in ["meshes[0].file", &placed, "more than the 33554432"] {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
    let small = StressMesh::new(6, 4);
    small.write_ply(&dir.path().join("big.ply")).unwrap();
    let scene = load(dir.path(), &many(10_000)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 10_000 * small.indices.len());
}

/// A glTF file of one triangle (accessor 0) with three instances' TRANSLATION (1), ROTATION (2)
/// and SCALE (3) accessors, and a SCALE with one element too few (4); `nodes` is its node
/// list (the scene places node 0).
fn instancing_gltf(nodes: &str) -> String {
    use base64::Engine as _;
    let floats: [&[f32]; 4] = [
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        &[-1.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.0, -1.0, 0.25],
        &[
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.382_683_43,
            0.0,
            0.923_879_5,
            0.5,
            0.5,
            0.5,
            0.5,
        ],
        &[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 1.0, 0.5, 3.0],
    ];
    let mut bytes = Vec::new();
    let mut views = Vec::new();
    for f in floats {
        views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#,
            bytes.len(),
            4 * f.len()
        ));
        bytes.extend(f.iter().flat_map(|x| x.to_le_bytes()));
    }
    let accessor = |view: usize, kind: &str, count: usize| {
        format!(
            r#"{{"bufferView": {view}, "componentType": 5126, "count": {count}, "type": "{kind}"}}"#
        )
    };
    let accessors = [
        accessor(0, "VEC3", 3),
        accessor(1, "VEC3", 3),
        accessor(2, "VEC4", 3),
        accessor(3, "VEC3", 3),
        accessor(3, "VEC3", 2),
    ]
    .join(", ");
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["EXT_mesh_gpu_instancing"],
"buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
"bufferViews": [{}], "accessors": [{accessors}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
"nodes": [{nodes}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        bytes.len(),
        base64::engine::general_purpose::STANDARD.encode(&bytes),
        views.join(", ")
    )
}

/// The instances' node: moved by its own translation, then the instances' T·R·S.
const INSTANCED_NODE: &str = r#"{"mesh": 0, "translation": [0.0, 0.0, 5.0], "extensions":
{"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 1, "ROTATION": 2, "SCALE": 3}}}}"#;

/// `model.gltf` holding `gltf`, placed by a scene in `dir`.
fn load_gltf(dir: &Path, gltf: &str) -> Result<Scene, SceneError> {
    std::fs::write(dir.join("model.gltf"), gltf).unwrap();
    load(
        dir,
        &format!("{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"model.gltf\"\nmaterial = \"white\"\n"),
    )
}

/// EXT_mesh_gpu_instancing places the mesh once per instance, each at the node's transform
/// times its T·R·S: the same triangles, bit for bit, as child nodes with those T·R·S under a
/// node with the instanced node's translation.
#[test]
fn gltf_gpu_instancing_is_child_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let instanced =
        load_gltf(dir.path(), &instancing_gltf(INSTANCED_NODE)).unwrap_or_else(|e| panic!("{e}"));
    // Listed last first: the hierarchy's walk takes the last child first.
    let children = r#"{"translation": [0.0, 0.0, 5.0], "children": [3, 2, 1]},
{"mesh": 0, "translation": [-1.0, 0.0, 0.0]},
{"mesh": 0, "translation": [1.0, 0.5, 0.0], "rotation": [0.0, 0.38268343, 0.0, 0.9238795], "scale": [2.0, 2.0, 2.0]},
{"mesh": 0, "translation": [0.0, -1.0, 0.25], "rotation": [0.5, 0.5, 0.5, 0.5], "scale": [1.0, 0.5, 3.0]}"#;
    let nodes = load_gltf(dir.path(), &instancing_gltf(children)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(instanced.triangles.len(), 3);
    assert_eq!(instanced.triangles, nodes.triangles);
    // The second instance: scaled by 2, turned 45° about y, moved by (1, 0.5, 0) and (0, 0, 5).
    let expected = Mat4::from_translation(Vec3::new(1.0, 0.5, 5.0))
        * Mat4::from_rotation_y(45f32.to_radians())
        * Mat4::from_scale(Vec3::splat(2.0));
    let v = instanced.triangles[1].vertices[1];
    assert!(
        (v - expected.transform_point3(Vec3::X)).length() < 1e-5,
        "{v}"
    );
}

/// Bad EXT_mesh_gpu_instancing data is an error naming the node, the attribute and the fault.
#[test]
fn bad_gltf_gpu_instancing_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let field = "nodes[0].extensions.EXT_mesh_gpu_instancing.attributes";
    let cases: [(&str, &[&str]); 5] = [
        (
            r#"{"TRANSLATION": 1, "SCALE": 4}"#,
            &["SCALE", "holds 2", "holds 3"],
        ),
        (
            r#"{"TRANSLATION": 2}"#,
            &["TRANSLATION: accessors[2]", "VEC4"],
        ),
        (
            r#"{"TRANSLATION": 9}"#,
            &["TRANSLATION: accessor 9 does not exist"],
        ),
        (r#"{"SHEAR": 1}"#, &["SHEAR: not an attribute"]),
        (r#"{"_ID": 1}"#, &["names none of"]),
    ];
    for (attributes, needles) in cases {
        let node = format!(
            r#"{{"mesh": 0, "extensions": {{"EXT_mesh_gpu_instancing": {{"attributes": {attributes}}}}}}}"#
        );
        let e = load_gltf(dir.path(), &instancing_gltf(&node)).expect_err(attributes);
        let message = e.to_string();
        assert!(message.contains(field), "{message}");
        for needle in needles {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
}

/// A glTF file's punctual lights are placed with every instance: tests/models'
/// lights-cameras.gltf (3 lights, its point light at (1, 3, 1)) placed twice has 6, the
/// second instance's point light moved with it.
#[test]
fn gltf_lights_are_placed_with_every_instance() {
    use glint::scene::light::LightKind;
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models/lights-cameras.gltf"),
        dir.path().join("model.gltf"),
    )
    .unwrap();
    let scene = load(
        dir.path(),
        &format!(
            "{MESH_SCENE_HEADER}\n[[meshes]]\nfile = \"model.gltf\"\nmaterial = \"white\"\n\
             instances = [{{}}, {{ translate = [0.0, 0.0, 2.0] }}]\n"
        ),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.lights.len(), 6);
    for (light, z) in [(&scene.lights[0], 1.0), (&scene.lights[3], 3.0)] {
        assert!(
            matches!(light.kind, LightKind::Point { position, .. } if position == Vec3::new(1.0, 3.0, z)),
            "{light:?}"
        );
    }
}
