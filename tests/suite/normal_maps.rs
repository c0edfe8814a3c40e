//! Normal maps (glTF's normalTexture with its scale): a flat quad whose 2 × 2 normal map tilts
//! each quarter a known way, its shading normals against the tangent-space formula glTF gives,
//! with tangents made by MikkTSpace (the file has none) and with the file's TANGENT, on the CPU
//! and, through the probe kernel, the GPU; a normal map without texture coordinates is refused.

use crate::common;

use base64::Engine as _;
use glam::Vec3;
use glint::scene::Scene;

/// The normal map's texels, top row first (the image's top is the quad's +y side): each
/// quarter tilted 37° towards +x, −x, +y and −y of the texture's frame.
const TEXELS: [[u8; 3]; 4] = [
    [204, 128, 230],
    [51, 128, 230],
    [128, 204, 230],
    [128, 51, 230],
];
const SCALE: f32 = 0.5;

/// A 1 × 1 quad in the z = 0 plane facing +z, u along +x and (glint's) v along +y, with the
/// normal map read nearest and clamped; `tangent`, when given, is every vertex's TANGENT.
fn quad_gltf(tangent: Option<[f32; 4]>, uvs: bool) -> String {
    let positions: [f32; 12] = [
        -0.5, -0.5, 0.0, 0.5, -0.5, 0.0, 0.5, 0.5, 0.0, -0.5, 0.5, 0.0,
    ];
    let normals: [f32; 12] = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
    // glTF's v is down: the quad's top (+y) is v = 0.
    let texcoords: [f32; 8] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let floats = |f: &[f32]| f.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = floats(&positions);
    bin.extend(floats(&normals));
    bin.extend(floats(&texcoords));
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0u8; 4]);
    if let Some(t) = tangent {
        bin.extend(floats(&[t, t, t, t].concat()));
    }
    let image = image::RgbImage::from_fn(2, 2, |x, y| image::Rgb(TEXELS[(y * 2 + x) as usize]));
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let b64 = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    let mut attributes = serde_json::json!({"POSITION": 0, "NORMAL": 1});
    if uvs {
        attributes["TEXCOORD_0"] = 2.into();
    }
    if tangent.is_some() {
        attributes["TANGENT"] = 4.into();
    }
    let mut json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "material": 0}]}],
        "materials": [{
            "pbrMetallicRoughness": {"metallicFactor": 0.0},
            "normalTexture": {"index": 0, "scale": SCALE}
        }],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"uri": format!("data:image/png;base64,{}", b64(&png))}],
        "buffers": [{
            "uri": format!("data:application/octet-stream;base64,{}", b64(&bin)),
            "byteLength": bin.len()
        }],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32},
            {"buffer": 0, "byteOffset": 128, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ]
    });
    if tangent.is_some() {
        json["bufferViews"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({"buffer": 0, "byteOffset": 144, "byteLength": 64}));
        json["accessors"].as_array_mut().unwrap().push(
            serde_json::json!({"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC4"}),
        );
    }
    json.to_string()
}

fn load(gltf: String) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("quad.gltf"), gltf).unwrap();
    let text = r#"[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 20.0
[render]
width = 4
height = 4
spp = 1
max_bounces = 1
[[meshes]]
file = "quad.gltf"
"#;
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).map_err(|e| e.to_string())
}

/// The grid point probe ray `i` aims at (tests/suite/shaders/probe.wgsl's probe_normal_map).
fn aim(i: u32) -> Vec3 {
    Vec3::new(
        -0.45 + 0.9 * ((i % 16) as f32 + 0.5) / 16.0,
        -0.45 + 0.9 * ((i / 16) as f32 + 0.5) / 16.0,
        0.0,
    )
}

const EYE: Vec3 = Vec3::new(0.0, 0.0, 5.0);

/// The shading normals the CPU finds along the probe's rays.
fn cpu_normals(scene: &glint::kernel::KernelScene) -> Vec<[f32; 4]> {
    use glint::cpu::geometry::intersect::intersect_scene;
    use glint::cpu::scene_refs::SceneRefs;
    use glint::cpu::textures::normal_map::normal_mapped;
    use glint::cpu::textures::texture::material_at;
    let refs = SceneRefs::of(scene, &scene.params);
    (0..256)
        .map(|i| {
            let ray = glint::cpu::core::ray::Ray {
                origin: EYE,
                dir: (aim(i) - EYE).normalize(),
            };
            let mut hit = intersect_scene(&refs.geometry(), &ray);
            let m = material_at(
                &refs.textures(),
                &scene.materials[hit.material as usize],
                hit.uv,
            );
            hit.shading_normal = normal_mapped(
                &refs.textures(),
                &hit,
                m.normal_texture,
                m.normal_scale,
                &scene.triangle_tangents[hit.index as usize],
                -ray.dir,
            );
            hit.shading_normal.extend(hit.t).to_array()
        })
        .collect()
}

/// glTF's formula, written out: the texel's quarter (from the aim's signs), decoded from 8
/// bits to [−1, 1], x and y scaled, in the frame (tangent, bitangent, +z).
fn expected(i: u32, tangent: Vec3, bitangent: Vec3) -> Vec3 {
    let p = aim(i);
    let (column, row) = ((p.x > 0.0) as usize, (p.y < 0.0) as usize);
    let c = Vec3::from(TEXELS[row * 2 + column].map(|b| b as f32 / 255.0 * 2.0 - 1.0));
    (SCALE * c.x * tangent + SCALE * c.y * bitangent + c.z * Vec3::Z).normalize()
}

fn check(gltf: String, tangent: Vec3, bitangent: Vec3) {
    check_scene(
        load(gltf).unwrap_or_else(|e| panic!("{e}")).kernel_scene(),
        tangent,
        bitangent,
    );
}

/// The quad's shading normals against [`expected`], on the CPU and through the probe on the
/// GPU.
fn check_scene(scene: glint::kernel::KernelScene, tangent: Vec3, bitangent: Vec3) {
    let cpu = cpu_normals(&scene);
    for (i, n) in cpu.iter().enumerate() {
        let want = expected(i as u32, tangent, bitangent);
        assert!(
            (Vec3::from_slice(&n[..3]) - want).abs().max_element() < 1e-5,
            "ray {i} at {}: {n:?}, want {want}",
            aim(i as u32)
        );
    }
    let Some(ctx) = common::gpu() else { return };
    let params = common::probe::ProbeParams {
        count: 256,
        position: EYE.to_array(),
        ..Default::default()
    };
    let gpu = common::probe::run_probe(ctx, "probe_normal_map", params, &scene);
    for (i, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
        for (a, b) in c.iter().zip(g) {
            assert!((a - b).abs() <= 1e-5, "ray {i}: CPU {c:?}, GPU {g:?}");
        }
    }
}

/// Without TANGENT, MikkTSpace's tangent runs along +x (increasing u) and the bitangent along
/// +y (increasing v, glTF's "green is up" convention).
#[test]
fn a_normal_map_with_generated_tangents_tilts_each_quarter() {
    check(quad_gltf(None, true), Vec3::X, Vec3::Y);
}

/// The file's TANGENT wins over MikkTSpace's, however it is laid out: tangent +y with w = 1
/// makes the bitangent normal × tangent = −x.
#[test]
fn the_files_tangents_are_used() {
    check(
        quad_gltf(Some([0.0, 1.0, 0.0, 1.0]), true),
        Vec3::Y,
        -Vec3::X,
    );
}

/// The quad's scene with its material given in the scene file: `normal_map` (TOML) on a `pbr`
/// material, the file's image (`n.png`, upscaled) and scale.
fn load_with_toml_material(gltf: String, normal_map: &str) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("quad.gltf"), gltf).unwrap();
    // TOML textures are bilinear and repeat: 32 × 32 texels a quarter keep every probe ray's
    // lookup within one quarter, so it reads that quarter's texel as the glTF file's nearest
    // lookup does.
    image::RgbImage::from_fn(64, 64, |x, y| {
        image::Rgb(TEXELS[(y / 32 * 2 + x / 32) as usize])
    })
    .save(dir.path().join("n.png"))
    .unwrap();
    let text = format!(
        "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         vfov = 20.0\n[render]\nwidth = 4\nheight = 4\nspp = 1\nmax_bounces = 1\n\
         [materials.bumpy]\ntype = \"pbr\"\nbase_color = [0.8, 0.8, 0.8]\nmetallic = 0.0\n\
         normal_map = {normal_map}\n[[meshes]]\nfile = \"quad.gltf\"\nmaterial = \"bumpy\"\n"
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    Scene::load(&path).map_err(|e| e.to_string())
}

/// A scene file's `normal_map` (a table with the file and scale) tilts the quad's quarters
/// as the glTF file's does, with MikkTSpace's tangents (the mesh has none), on both devices;
/// the plain file name form reads the same image at scale 1.
#[test]
fn a_toml_normal_map_tilts_each_quarter() {
    let table = format!("{{ file = \"n.png\", scale = {SCALE} }}");
    let scene =
        load_with_toml_material(quad_gltf(None, true), &table).unwrap_or_else(|e| panic!("{e}"));
    let m = scene.materials.iter().find(|m| m.name == "bumpy").unwrap();
    assert_eq!(m.normal_texture.map(|(_, s)| s), Some(SCALE));
    check_scene(scene.kernel_scene(), Vec3::X, Vec3::Y);
    let scene = load_with_toml_material(quad_gltf(None, true), "\"n.png\"")
        .unwrap_or_else(|e| panic!("{e}"));
    let m = scene.materials.iter().find(|m| m.name == "bumpy").unwrap();
    assert_eq!(m.normal_texture.map(|(_, s)| s), Some(1.0));
}

/// Bad `normal_map` values, and a TOML normal map on a mesh without texture coordinates, are
/// errors naming the field (or the mesh file and material) and what is wrong.
#[test]
fn bad_toml_normal_maps_are_named_errors() {
    for (value, uvs, needles) in [
        (
            "\"missing.png\"",
            true,
            vec!["materials.bumpy.normal_map", "missing.png"],
        ),
        (
            "{ file = \"n.png\", scale = \"big\" }",
            true,
            vec!["materials.bumpy.normal_map.scale", "must be a number"],
        ),
        (
            "{ file = \"n.png\", scale = inf }",
            true,
            vec!["materials.bumpy.normal_map.scale", "[-1e6, 1e6]"],
        ),
        (
            "{ scale = 1.0 }",
            true,
            vec!["materials.bumpy.normal_map.file", "missing"],
        ),
        (
            "{ texture = \"n.png\" }",
            true,
            vec!["materials.bumpy.normal_map", "unknown key: texture"],
        ),
        (
            "0.5",
            true,
            vec!["materials.bumpy.normal_map", "must be \"file.png\""],
        ),
        (
            "\"n.png\"",
            false,
            vec!["quad.gltf", "bumpy", "normal map", "texture coordinates"],
        ),
    ] {
        let message = load_with_toml_material(quad_gltf(None, uvs), value)
            .expect_err("the scene should be refused");
        for needle in needles {
            assert!(
                message.contains(needle),
                "{value}: {message:?} lacks {needle:?}"
            );
        }
    }
}

/// A normal map on triangles without texture coordinates cannot be laid out: an error naming
/// the file, the material and what is missing.
#[test]
fn a_normal_map_without_texture_coordinates_is_an_error() {
    let message = load(quad_gltf(None, false)).expect_err("the file should be refused");
    for needle in ["quad.gltf", "material0", "normal map", "TEXCOORD_0"] {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}
