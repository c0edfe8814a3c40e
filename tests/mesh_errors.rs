//! Bad meshes: each a clear error naming the scene, the line, the field and, where the reader
//! gives it, the line or element of the mesh file; degenerate triangles are skipped with a
//! warning. (The CLI's exit code 2 for these is checked at the end.)

mod common;

use glint::scene::Scene;

const SCENE: &str = r#"[camera]
eye = [0.0, 0.0, -5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0

[render]
width = 8
height = 8
spp = 1
max_bounces = 1

[materials.white]
type = "diffuse"
color = [0.7, 0.7, 0.7]

[[meshes]]
file = "MESH"
material = "white"
"#;

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// Writes `files` into a fresh folder with the scene (its mesh file named `mesh`, and `extra`
/// lines appended to the [[meshes]] entry), and loads it.
fn load(
    mesh: &str,
    files: &[(&str, &[u8])],
    extra: &str,
) -> (Result<Scene, String>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    let text = SCENE.replace("MESH", mesh) + extra;
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    (Scene::load(&path).map_err(|e| e.to_string()), dir)
}

fn assert_error(mesh: &str, files: &[(&str, &[u8])], extra: &str, needles: &[&str]) {
    let (result, _dir) = load(mesh, files, extra);
    let message = result.expect_err("the scene should be rejected");
    assert!(message.contains("scene.toml:"), "{message}");
    assert!(message.contains("meshes[0]."), "{message}");
    for needle in needles {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}

#[test]
fn a_good_obj_loads() {
    let (scene, _dir) = load("t.obj", &[("t.obj", TRIANGLE_OBJ.as_bytes())], "");
    assert_eq!(scene.unwrap().triangles.len(), 1);
}

#[test]
fn missing_file() {
    assert_error("nope.obj", &[], "", &["nope.obj", "no such file"]);
}

#[test]
fn unknown_extension() {
    assert_error(
        "t.stl",
        &[("t.stl", b"solid")],
        "",
        &["unknown mesh format", ".stl", ".obj"],
    );
}

#[test]
fn malformed_obj_names_the_line() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x 0\nf 1 2 3\n";
    assert_error(
        "t.obj",
        &[("t.obj", obj.as_bytes())],
        "",
        &["t.obj", "line 4", "malformed OBJ"],
    );
}

#[test]
fn malformed_ply_and_gltf() {
    assert_error(
        "t.ply",
        &[("t.ply", b"ply\nformat ascii 1.0\nelement vertex x\n")],
        "",
        &["t.ply", "malformed PLY"],
    );
    assert_error(
        "t.gltf",
        &[(
            "t.gltf",
            b"{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [",
        )],
        "",
        &["t.gltf", "malformed glTF"],
    );
}

#[test]
fn non_finite_vertices() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
    assert_error(
        "t.obj",
        &[("t.obj", obj.as_bytes())],
        "",
        &["vertex 2", "not finite"],
    );
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 1e39\n0 1 0\n3 0 1 2\n";
    assert_error(
        "t.ply",
        &[("t.ply", ply.as_bytes())],
        "",
        &["vertex 1", "not finite"],
    );
}

#[test]
fn indices_out_of_range() {
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    assert_error(
        "t.ply",
        &[("t.ply", ply.as_bytes())],
        "",
        &["face 0", "vertex 7", "only 3 vertices"],
    );
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
    assert_error(
        "t.obj",
        &[("t.obj", obj.as_bytes())],
        "",
        &["t.obj", "out of bounds"],
    );
}

#[test]
fn zero_triangles() {
    assert_error("t.obj", &[("t.obj", b"v 0 0 0\n")], "", &["no triangles"]);
    let degenerate = "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
    assert_error(
        "t.obj",
        &[("t.obj", degenerate.as_bytes())],
        "",
        &["no triangles", "degenerate"],
    );
}

#[test]
fn degenerate_transforms() {
    let files: &[(&str, &[u8])] = &[("t.obj", TRIANGLE_OBJ.as_bytes())];
    assert_error(
        "t.obj",
        files,
        "scale = 0.0\n",
        &["meshes[0].scale", "degenerate transform"],
    );
    assert_error(
        "t.obj",
        files,
        "scale = [1.0, -1.0, 1.0]\n",
        &["meshes[0].scale", "> 0"],
    );
    assert_error(
        "t.obj",
        files,
        "translate = [1.0, nan, 0.0]\n",
        &["meshes[0].translate", "finite"],
    );
}

#[test]
fn a_mesh_without_materials_needs_one() {
    let text = SCENE.replace("material = \"white\"\n", "");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.obj"), TRIANGLE_OBJ).unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text.replace("MESH", "t.obj")).unwrap();
    let message = Scene::load(&path).unwrap_err().to_string();
    assert!(message.contains("no material"), "{message}");
}

/// The file's own materials, when the scene names none: OBJ .mtl and glTF's PBR factors.
#[test]
fn file_materials_are_mapped() {
    use glint::scene::MaterialKind;
    let mtl = "newmtl lamp\nKd 0.2 0.3 0.4\nKe 4 5 6\nnewmtl glass\nKd 1 1 1\nd 0.5\nNi 1.33\nnewmtl mirror\nKs 0.9 0.9 0.9\nillum 3\nmap_Kd wood.png\n";
    let obj = "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl lamp\nf 1 2 3\nusemtl glass\nf 2 4 3\nusemtl mirror\nf 1 3 4\n";
    let text = SCENE
        .replace("material = \"white\"\n", "")
        .replace("MESH", "t.obj");
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.obj"), obj).unwrap();
    std::fs::write(dir.path().join("t.mtl"), mtl).unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let by_name = |n: &str| {
        scene
            .materials
            .iter()
            .find(|m| m.name == n)
            .unwrap_or_else(|| panic!("{n}: {:?}", scene.materials))
    };
    let lamp = by_name("t.obj/lamp");
    assert_eq!(lamp.kind, MaterialKind::Diffuse);
    assert_eq!(lamp.emitted_radiance, glam::Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(
        by_name("t.obj/glass").kind,
        MaterialKind::Dielectric { ior: 1.33 }
    );
    assert_eq!(by_name("t.obj/mirror").kind, MaterialKind::Specular);
    assert_eq!(scene.triangles.len(), 3);
}

#[test]
fn the_cli_exits_with_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, SCENE.replace("MESH", "missing.ply")).unwrap();
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &scene, &out);
    common::assert_refused(&run, &out, &["missing.ply"]);
}

#[test]
fn degenerate_triangles_are_skipped_with_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 2\n";
    std::fs::write(dir.path().join("t.obj"), obj).unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, SCENE.replace("MESH", "t.obj")).unwrap();
    let out = dir.path().join("out.png");
    let result = common::run_render("--cpu", &scene, &out);
    assert_eq!(result.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&result.stderr);
    let warnings: Vec<_> = stderr.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("skipped 2 degenerate"), "{stderr}");
}
