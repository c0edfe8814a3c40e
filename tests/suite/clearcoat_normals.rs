//! KHR_materials_clearcoat's clearcoatNormalTexture: the coat's own normal map, through the
//! same tangent frame as the base's normalTexture. Without one the coat keeps the unmapped
//! (vertex) normal, even where the base has a normal map, as the extension says. Each test
//! writes a generated glTF quad facing a smooth-coated camera-side lamp: where the coat's
//! normal faces the camera, the coat mirrors the lamp; a normal map tilted 37° sends that
//! reflection 74° away.

use crate::common;

use base64::Engine as _;
use common::{render_with_variance, PathAgreement};
use glint::cpu::integrator::renderer::CpuRenderer;
use glint::kernel::types::NO_TEXTURE;
use glint::kernel::KernelScene;
use glint::scene::{MaterialKind, Scene};

/// A normal-map texel tilted 37° towards +x (the tangent, increasing u).
const TILTED: [u8; 3] = [204, 128, 230];

/// Which normal maps the quad's material has: the base's (normalTexture) and the coat's
/// (clearcoatNormalTexture, at `coat_scale`), both the tilted texel.
#[derive(Clone, Copy)]
struct Maps {
    base: bool,
    coat: Option<f32>,
}

/// A 1 × 1 quad in the z = 0 plane facing +z (no TANGENT: MikkTSpace's runs along +x) with a
/// dark rough base under a smooth coat, and the normal maps `maps`.
fn quad_gltf(maps: Maps) -> String {
    let positions: [f32; 12] = [
        -0.5, -0.5, 0.0, 0.5, -0.5, 0.0, 0.5, 0.5, 0.0, -0.5, 0.5, 0.0,
    ];
    let normals: [f32; 12] = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
    let texcoords: [f32; 8] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let floats = |f: &[f32]| f.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = floats(&positions);
    bin.extend(floats(&normals));
    bin.extend(floats(&texcoords));
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0u8; 4]);
    let image = image::RgbImage::from_pixel(1, 1, image::Rgb(TILTED));
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let b64 = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    let mut coat = serde_json::json!({"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.05});
    if let Some(scale) = maps.coat {
        coat["clearcoatNormalTexture"] = serde_json::json!({"index": 0, "scale": scale});
    }
    let mut material = serde_json::json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.1, 0.1, 0.1, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 0.7
        },
        "extensions": {"KHR_materials_clearcoat": coat}
    });
    if maps.base {
        material["normalTexture"] = serde_json::json!({"index": 0});
    }
    serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_clearcoat"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3,
            "material": 0
        }]}],
        "materials": [material],
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
    })
    .to_string()
}

/// The quad filling the view of a camera 5 in front of it, a 2 × 2 lamp just behind the
/// camera facing the quad (the coat mirrors it where its normal faces the camera).
fn scene_text(size: u32, seed: u32) -> String {
    format!(
        r#"[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 9.0
[render]
width = {size}
height = {size}
spp = 1
max_bounces = 2
seed = {seed}
[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
strength = 5.0
[[quads]]
corner = [-1.0, -1.0, 6.0]
u = [0.0, 2.0, 0.0]
v = [2.0, 0.0, 0.0]
material = "lamp"
[[meshes]]
file = "quad.gltf"
"#
    )
}

/// Writes the quad with `maps` and its scene into a fresh folder.
fn write(maps: Maps, size: u32, seed: u32) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("quad.gltf"), quad_gltf(maps)).unwrap();
    std::fs::write(dir.path().join("scene.toml"), scene_text(size, seed)).unwrap();
    dir
}

fn load(maps: Maps, size: u32, seed: u32) -> Scene {
    let dir = write(maps, size, seed);
    Scene::load(&dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// The mean of an image's channels and its standard error, from the variance image (the
/// pixels' means are independent, so the variances add).
fn mean_and_error(scene: &KernelScene, spp: u32) -> (f64, f64) {
    let (image, variance) = render_with_variance(&mut CpuRenderer::new(scene), spp);
    let n = (image.pixels.len() * 3) as f64;
    let mean = image
        .pixels
        .iter()
        .flatten()
        .map(|&v| v as f64)
        .sum::<f64>()
        / n;
    let var = variance
        .pixels
        .iter()
        .flatten()
        .map(|&v| v as f64)
        .sum::<f64>()
        / (n * n);
    (mean, var.sqrt())
}

const NO_MAPS: Maps = Maps {
    base: false,
    coat: None,
};

/// The coat's normal map reaches the kernel's material with its scale, and the quad gets
/// tangents for it though the base has no normal map.
#[test]
fn a_clearcoat_normal_texture_reaches_the_kernel() {
    let scene = load(
        Maps {
            base: false,
            coat: Some(0.5),
        },
        4,
        1,
    );
    let index = scene.triangles[0].material as usize;
    let MaterialKind::Pbr { layers, .. } = scene.materials[index].kind else {
        panic!("{:?}", scene.materials[index].kind)
    };
    assert_eq!(layers.clearcoat_normal_texture.map(|(_, s)| s), Some(0.5));
    let k = scene.kernel_scene();
    let m = k.materials[index];
    assert_ne!(m.clearcoat_normal_texture, NO_TEXTURE);
    assert_eq!(m.clearcoat_normal_scale, 0.5);
    assert_eq!(m.normal_texture, NO_TEXTURE);
    assert_eq!(k.triangle_tangents.len(), k.triangles.len());
    assert!(k.triangle_tangents[0].t0[0] > 0.99, "MikkTSpace's +x");
    // Without the map, no tangents are made.
    let plain = load(NO_MAPS, 4, 1).kernel_scene();
    assert!(plain.triangle_tangents.len() < plain.triangles.len());
}

/// The file renders without a warning about the coat's normal map (it used to be ignored with
/// one).
#[test]
fn a_clearcoat_normal_texture_renders_without_a_warning() {
    let dir = write(
        Maps {
            base: false,
            coat: Some(1.0),
        },
        8,
        1,
    );
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(!stderr.lines().any(|l| l.contains("warning")), "{stderr}");
    assert!(out.exists());
}

/// The coat's tilted normal map sends the coat's reflection of the lamp away from the camera:
/// the quad renders darker than the same file without the map, by far more than the renders'
/// noise (10 standard errors of the difference of the image means, from the variance images).
/// Without a coat normal map the coat keeps the vertex normal even under a base normal map, so
/// it still mirrors the lamp there; with the base's own map given as the coat's too it does not.
#[test]
fn the_coats_normal_map_moves_its_reflection() {
    let spp = 16;
    let mean = |maps| mean_and_error(&load(maps, 24, 3).kernel_scene(), spp);
    let differ = |(a, ea): (f64, f64), (b, eb): (f64, f64)| (a - b) / (ea * ea + eb * eb).sqrt();
    let plain = mean(NO_MAPS);
    let coat_mapped = mean(Maps {
        base: false,
        coat: Some(1.0),
    });
    let base_mapped = mean(Maps {
        base: true,
        coat: None,
    });
    let both_mapped = mean(Maps {
        base: true,
        coat: Some(1.0),
    });
    eprintln!(
        "image means: plain {plain:?}, coat mapped {coat_mapped:?}, base mapped \
         {base_mapped:?}, both {both_mapped:?}"
    );
    assert!(
        differ(plain, coat_mapped) > 10.0,
        "{plain:?} vs {coat_mapped:?}"
    );
    assert!(
        differ(base_mapped, both_mapped) > 10.0,
        "{base_mapped:?} vs {both_mapped:?}"
    );
}

/// A coat normal map at scale 0 is the unmapped normal: the same paths as no coat map, under
/// a tilted base normal map (the base's map does not reach the coat), on the CPU.
#[test]
fn a_coat_normal_map_at_scale_0_is_the_vertex_normal() {
    let mut agreement = PathAgreement::default();
    for seed in [1, 2] {
        let without = load(
            Maps {
                base: true,
                coat: None,
            },
            32,
            seed,
        )
        .kernel_scene();
        let flat = load(
            Maps {
                base: true,
                coat: Some(0.0),
            },
            32,
            seed,
        )
        .kernel_scene();
        agreement.add(
            &common::render_cpu(&without, 1),
            &common::render_cpu(&flat, 1),
        );
    }
    agreement.check(0.99);
}

/// The GPU traces the CPU's paths through the coat's and the base's normal maps, one path per
/// pixel (see tests/suite/gpu_vs_cpu.rs for why 99%).
#[test]
fn gpu_and_cpu_trace_the_same_paths_through_coat_normal_maps() {
    let Some(ctx) = common::gpu() else { return };
    let mut agreement = PathAgreement::default();
    for (seed, maps) in [
        (
            1,
            Maps {
                base: false,
                coat: Some(1.0),
            },
        ),
        (
            2,
            Maps {
                base: true,
                coat: Some(0.7),
            },
        ),
    ] {
        let scene = load(maps, 32, seed).kernel_scene();
        agreement.add(
            &common::render_cpu(&scene, 1),
            &common::render_gpu(ctx, &scene, 1),
        );
    }
    agreement.check(0.99);
}

/// The quad's scene with its material from the scene file: a dark rough `pbr` base under a
/// smooth coat, with `coat_map` (a TOML value) as its `clearcoat_normal_map` when given, and
/// `tilted.png` (the tilted texel) beside it.
fn write_toml_material(coat_map: Option<&str>, extra: &str) -> tempfile::TempDir {
    let dir = write(NO_MAPS, 24, 3);
    image::RgbImage::from_pixel(4, 4, image::Rgb(TILTED))
        .save(dir.path().join("tilted.png"))
        .unwrap();
    let map = coat_map.map_or(String::new(), |m| format!("clearcoat_normal_map = {m}\n"));
    let text = scene_text(24, 3).replace(
        "[[meshes]]\nfile = \"quad.gltf\"\n",
        &format!(
            "[materials.coated]\ntype = \"pbr\"\nbase_color = [0.1, 0.1, 0.1]\nroughness = 0.7\n\
             clearcoat = 1.0\nclearcoat_roughness = 0.05\n{map}{extra}\
             [[meshes]]\nfile = \"quad.gltf\"\nmaterial = \"coated\"\n"
        ),
    );
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    dir
}

fn load_toml_material(coat_map: Option<&str>, extra: &str) -> Result<Scene, String> {
    let dir = write_toml_material(coat_map, extra);
    Scene::load(&dir.path().join("scene.toml")).map_err(|e| e.to_string())
}

/// A scene file's `clearcoat_normal_map` (as `normal_map`: a file name, or a table with the
/// file and scale) reaches the kernel with its scale and sends the coat's reflection of the
/// lamp away, as the glTF file's clearcoatNormalTexture does: the quad renders darker than
/// without it, by more than 10 standard errors of the difference of the image means.
#[test]
fn a_toml_clearcoat_normal_map_moves_the_coats_reflection() {
    let spp = 16;
    let scene = load_toml_material(Some("{ file = \"tilted.png\", scale = 0.5 }"), "")
        .unwrap_or_else(|e| panic!("{e}"));
    let m = scene.materials.iter().find(|m| m.name == "coated").unwrap();
    let MaterialKind::Pbr { layers, .. } = m.kind else {
        panic!("{:?}", m.kind)
    };
    assert_eq!(layers.clearcoat_normal_texture.map(|(_, s)| s), Some(0.5));
    assert_eq!(m.normal_texture, None);
    let k = scene.kernel_scene();
    assert_eq!(k.triangle_tangents.len(), k.triangles.len());
    let mean = |map| {
        let scene = load_toml_material(map, "").unwrap_or_else(|e| panic!("{e}"));
        mean_and_error(&scene.kernel_scene(), spp)
    };
    let plain = mean(None);
    let mapped = mean(Some("\"tilted.png\""));
    eprintln!("image means: plain {plain:?}, coat mapped {mapped:?}");
    let differ = (plain.0 - mapped.0) / (plain.1 * plain.1 + mapped.1 * mapped.1).sqrt();
    assert!(differ > 10.0, "{plain:?} vs {mapped:?}");
}

/// Bad `clearcoat_normal_map` values are errors naming the field, as `normal_map`'s are, and
/// so are one without a coat and one on a material that is not pbr; the command line refuses
/// the scene with exit status 2.
#[test]
fn bad_toml_clearcoat_normal_maps_are_named_errors() {
    let field = "materials.coated.clearcoat_normal_map";
    for (value, extra, needles) in [
        ("\"missing.png\"", "", vec![field, "missing.png"]),
        (
            "{ file = \"tilted.png\", scale = \"big\" }",
            "",
            vec![
                "materials.coated.clearcoat_normal_map.scale",
                "must be a number",
            ],
        ),
        (
            "{ texture = \"tilted.png\" }",
            "",
            vec![field, "unknown key: texture"],
        ),
        ("0.5", "", vec![field, "must be \"file.png\""]),
    ] {
        let message = load_toml_material(Some(value), extra).expect_err(value);
        for needle in needles {
            assert!(
                message.contains(needle),
                "{value}: {message:?} lacks {needle:?}"
            );
        }
    }
    // Without a coat it would map nothing.
    let dir = write_toml_material(Some("\"tilted.png\""), "");
    let path = dir.path().join("scene.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("clearcoat = 1.0\n", "")).unwrap();
    let message = Scene::load(&path).map(|_| ()).unwrap_err().to_string();
    assert!(
        message.contains(field) && message.contains("no coat"),
        "{message}"
    );
    // Not on other types.
    std::fs::write(
        &path,
        scene_text(8, 1).replace(
            "[[meshes]]\nfile = \"quad.gltf\"\n",
            "[materials.coated]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\n\
             clearcoat_normal_map = \"tilted.png\"\n\
             [[meshes]]\nfile = \"quad.gltf\"\nmaterial = \"coated\"\n",
        ),
    )
    .unwrap();
    let message = Scene::load(&path).map(|_| ()).unwrap_err().to_string();
    assert!(
        message.contains(field) && message.contains("does not apply"),
        "{message}"
    );
    // The command line: exit 2, naming the file and the field.
    let dir = write_toml_material(Some("\"missing.png\""), "");
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
    common::assert_refused(&run, &out, &["scene.toml", field, "missing.png"]);
}
