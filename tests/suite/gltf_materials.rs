//! glTF materials as glint reads them: the metallic-roughness model and its extensions onto
//! `pbr`, images embedded in the file, and the texture maps glTF defines. Each test writes a
//! small generated glTF file (one triangle) beside a scene that uses the file's materials.

use crate::common;

use glam::Vec3;
use glint::scene::{MaterialKind, Scene};

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

[[meshes]]
file = "t.gltf"
"#;

/// One triangle with normals and texture coordinates in an external buffer, `tri.bin`, and
/// `material` as its only material.
fn triangle_gltf(material: serde_json::Value) -> (serde_json::Value, Vec<u8>) {
    let floats: [f32; 24] = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, // positions
        0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, // normals
        0.0, 0.0, 1.0, 0.0, 0.0, 1.0, // texture coordinates
    ];
    let mut bin: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3,
            "material": 0
        }]}],
        "materials": [material],
        "buffers": [{"uri": "tri.bin", "byteLength": 104}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 36},
            {"buffer": 0, "byteOffset": 72, "byteLength": 24},
            {"buffer": 0, "byteOffset": 96, "byteLength": 6}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ]
    });
    (json, bin)
}

/// Writes the glTF `json` and its buffer with the scene into a fresh folder.
fn write(json: &serde_json::Value, bin: &[u8]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.gltf"), serde_json::to_vec(json).unwrap()).unwrap();
    std::fs::write(dir.path().join("tri.bin"), bin).unwrap();
    std::fs::write(dir.path().join("scene.toml"), SCENE).unwrap();
    dir
}

fn load(json: &serde_json::Value, bin: &[u8]) -> Result<Scene, String> {
    let dir = write(json, bin);
    Scene::load(&dir.path().join("scene.toml")).map_err(|e| e.to_string())
}

/// The scene material the file's material became.
fn loaded_material(material: serde_json::Value) -> glint::scene::Material {
    let (json, bin) = triangle_gltf(material);
    let scene = load(&json, &bin).unwrap_or_else(|e| panic!("{e}"));
    scene.materials[scene.triangles[0].material as usize].clone()
}

/// The file whose triangle has `material` is refused, the message naming the scene file's
/// line, the mesh field, the glTF file and every needle.
fn assert_material_refused(material: serde_json::Value, needles: &[&str]) {
    let (json, bin) = triangle_gltf(material);
    let message = load(&json, &bin).expect_err("the material should be refused");
    for needle in ["scene.toml:", "meshes[0].file", "t.gltf: "]
        .iter()
        .chain(needles)
    {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}

/// The warning lines `glint render --cpu` prints for the file.
fn render_warnings(json: &serde_json::Value, bin: &[u8]) -> Vec<String> {
    let dir = write(json, bin);
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    stderr
        .lines()
        .filter(|l| l.contains("warning"))
        .map(str::to_owned)
        .collect()
}

#[test]
fn metallic_roughness_factors_and_extensions_become_pbr() {
    let m = loaded_material(serde_json::json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.5, 0.25, 1.0],
            "metallicFactor": 0.25,
            "roughnessFactor": 0.6
        },
        "emissiveFactor": [0.5, 0.25, 1.0],
        "extensions": {
            "KHR_materials_ior": {"ior": 1.33},
            "KHR_materials_specular": {
                "specularFactor": 0.7,
                "specularColorFactor": [1.0, 0.5, 2.0]
            },
            "KHR_materials_emissive_strength": {"emissiveStrength": 4.0}
        }
    }));
    assert_eq!(
        m.kind,
        MaterialKind::Pbr {
            roughness: 0.6,
            metallic: 0.25,
            ior: 1.33,
            specular: 0.7,
            specular_color: Vec3::new(1.0, 0.5, 2.0),
            transmission: 0.0,
            transmission_texture: None,
            attenuation_color: Vec3::ONE,
            attenuation_distance: None,
            layers: Default::default(),
        }
    );
    assert_eq!(m.color, Vec3::new(0.8, 0.5, 0.25));
    assert_eq!(m.emitted_radiance, Vec3::new(2.0, 1.0, 4.0));
    assert_eq!(m.name, "t.gltf/material0");
}

/// An empty material is glTF's default: white, fully metallic, fully rough (not glint's TOML
/// defaults, roughness 0.5 and metallic 0).
#[test]
fn absent_factors_take_gltfs_defaults() {
    let m = loaded_material(serde_json::json!({}));
    assert_eq!(
        m.kind,
        MaterialKind::Pbr {
            roughness: 1.0,
            metallic: 1.0,
            ior: 1.5,
            specular: 1.0,
            specular_color: Vec3::ONE,
            transmission: 0.0,
            transmission_texture: None,
            attenuation_color: Vec3::ONE,
            attenuation_distance: None,
            layers: Default::default(),
        }
    );
    assert_eq!(m.color, Vec3::ONE);
    assert_eq!(m.emitted_radiance, Vec3::ZERO);
}

/// KHR_materials_transmission and KHR_materials_volume become the pbr material's
/// transmission and attenuation (rough, partly transmissive: no warning, and none for the
/// extensions, which glint reads entirely; thicknessFactor is for rasterisers and ignored),
/// and both may be required.
#[test]
fn transmission_and_volume_become_pbr_without_a_warning() {
    let material = serde_json::json!({
        "pbrMetallicRoughness": {"roughnessFactor": 0.3, "metallicFactor": 0.0},
        "extensions": {
            "KHR_materials_transmission": {"transmissionFactor": 0.4},
            "KHR_materials_volume": {
                "thicknessFactor": 0.5,
                "attenuationColor": [0.9, 0.5, 0.25],
                "attenuationDistance": 2.0
            },
            "KHR_materials_ior": {"ior": 1.4}
        }
    });
    let m = loaded_material(material.clone());
    assert_eq!(
        m.kind,
        MaterialKind::Pbr {
            roughness: 0.3,
            metallic: 0.0,
            ior: 1.4,
            specular: 1.0,
            specular_color: Vec3::ONE,
            transmission: 0.4,
            transmission_texture: None,
            attenuation_color: Vec3::new(0.9, 0.5, 0.25),
            attenuation_distance: Some(2.0),
            layers: Default::default(),
        }
    );
    let (mut json, bin) = triangle_gltf(material);
    json["extensionsUsed"] = serde_json::json!([
        "KHR_materials_transmission",
        "KHR_materials_volume",
        "KHR_materials_ior"
    ]);
    json["extensionsRequired"] =
        serde_json::json!(["KHR_materials_transmission", "KHR_materials_volume"]);
    let warnings = render_warnings(&json, &bin);
    assert!(
        !warnings
            .iter()
            .any(|w| w.contains("transmission") || w.contains("volume")),
        "{warnings:?}"
    );
    // The kernel's material carries them (attenuation 0 stands for glTF's +∞).
    let scene = load(&json, &bin).unwrap();
    let index = scene.triangles[0].material as usize;
    let k = scene.kernel_scene().materials[index];
    assert_eq!(
        (k.transmission, k.attenuation_color, k.attenuation_distance),
        (0.4, [0.9, 0.5, 0.25], 2.0)
    );
    let plain = load(&triangle_gltf(serde_json::json!({})).0, &bin).unwrap();
    let k = plain.kernel_scene().materials[plain.triangles[0].material as usize];
    assert_eq!(
        (k.transmission, k.attenuation_color, k.attenuation_distance),
        (0.0, [1.0; 3], 0.0)
    );
}

/// Factors outside glTF's ranges are errors naming the material and the factor.
#[test]
fn factors_out_of_range_are_errors() {
    for (material, needles) in [
        (
            serde_json::json!({"pbrMetallicRoughness": {"roughnessFactor": 1.5}}),
            &["material0", "roughnessFactor must be in [0, 1]", "1.5"][..],
        ),
        (
            serde_json::json!({"pbrMetallicRoughness": {"metallicFactor": -0.5}}),
            &["material0", "metallicFactor must be in [0, 1]"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_specular": {"specularFactor": 2}}}),
            &["material0", "specularFactor must be in [0, 1]"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_specular":
                {"specularColorFactor": [1, -1, 1]}}}),
            &["material0", "specularColorFactor must be ≥ 0"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_transmission":
                {"transmissionFactor": 1.5}}}),
            &["material0", "transmissionFactor must be in [0, 1]", "1.5"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_transmission":
                {"transmissionFactor": -0.25}}}),
            &["material0", "transmissionFactor must be in [0, 1]"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_volume":
                {"attenuationDistance": 0}}}),
            &["material0", "attenuationDistance must be > 0"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_volume":
                {"attenuationDistance": -3}}}),
            &["material0", "attenuationDistance must be > 0", "-3"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_volume":
                {"attenuationColor": [1.5, 0.5, 0.5]}}}),
            &["material0", "attenuationColor must be in [0, 1]"][..],
        ),
        (
            serde_json::json!({"extensions": {"KHR_materials_volume":
                {"attenuationColor": [0.5, -0.5, 0.5]}}}),
            &["material0", "attenuationColor must be in [0, 1]"][..],
        ),
    ] {
        assert_material_refused(material, needles);
    }
}

/// A 2×2 PNG with these texels, top row first.
fn png(texels: [[u8; 3]; 4]) -> Vec<u8> {
    let image = image::RgbImage::from_fn(2, 2, |x, y| image::Rgb(texels[(y * 2 + x) as usize]));
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

const COLOR_TEXELS: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [128, 64, 32]];
/// Roughness in green, metallic in blue; red is glTF's occlusion, unused.
const METALLIC_ROUGHNESS_TEXELS: [[u8; 3]; 4] =
    [[9, 255, 0], [9, 128, 255], [9, 0, 64], [9, 51, 204]];

/// A binary glTF: the triangle's buffer then `images` in its BIN chunk (each in a buffer
/// view), with `edit` applied to the JSON.
fn glb(
    material: serde_json::Value,
    images: &[Vec<u8>],
    edit: impl FnOnce(&mut serde_json::Value),
) -> Vec<u8> {
    let (mut json, mut bin) = triangle_gltf(material);
    json["images"] = serde_json::json!([]);
    for image in images {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let view = json["bufferViews"].as_array().unwrap().len();
        json["bufferViews"].as_array_mut().unwrap().push(
            serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": image.len()}),
        );
        json["images"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({"bufferView": view, "mimeType": "image/png"}));
        bin.extend(image);
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    json["buffers"] = serde_json::json!([{"byteLength": bin.len()}]);
    edit(&mut json);
    let mut text = serde_json::to_vec(&json).unwrap();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(text);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

fn load_glb(bytes: &[u8]) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.glb"), bytes).unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, SCENE.replace("t.gltf", "t.glb")).unwrap();
    Scene::load(&scene).map_err(|e| e.to_string())
}

/// The textured material: base colour from a data: URI, metallic-roughness from the .glb's
/// buffer view, all multiplying their factors; the base colour's image is also the
/// transmission texture (its red channel, linear).
fn textured_glb() -> Vec<u8> {
    use base64::Engine as _;
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png(COLOR_TEXELS))
    );
    let material = serde_json::json!({"pbrMetallicRoughness": {
        "baseColorFactor": [0.5, 1.0, 0.25, 1.0],
        "metallicFactor": 0.5,
        "roughnessFactor": 0.8,
        "baseColorTexture": {"index": 0},
        "metallicRoughnessTexture": {"index": 1}
    }, "extensions": {"KHR_materials_transmission": {
        "transmissionFactor": 0.5,
        "transmissionTexture": {"index": 0}
    }}});
    glb(material, &[png(METALLIC_ROUGHNESS_TEXELS)], |g| {
        g["images"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({"uri": uri}));
        g["textures"] = serde_json::json!([{"source": 1}, {"source": 0}]);
    })
}

/// At each texel centre, on both devices, the material's colour is baseColorFactor × the
/// sRGB-decoded texel, its roughness roughnessFactor × green and its metallic metallicFactor
/// × blue, its transmission transmissionFactor × red (the texels are exact at power-of-two texel centres, tests/suite/textures.rs; the
/// products are the same f32 operations on both sides, so they agree to an ulp or two).
#[test]
fn embedded_textures_multiply_their_factors_on_both_devices() {
    use glint::cpu::textures::texture::{both_sets, material_at, Textures};
    let scene = load_glb(&textured_glb()).unwrap_or_else(|e| panic!("{e}"));
    let index = scene.triangles[0].material;
    let scene = scene.kernel_scene();
    let material = scene.materials[index as usize];
    let textures = Textures {
        descriptors: &scene.textures,
        texels: &scene.texels,
    };
    // Kernel texture coordinates have v up: texel (x, y) from the image's top left is at
    // ((x + 0.5)/2, 1 − (y + 0.5)/2).
    let centres: Vec<(usize, glam::Vec2)> = (0..4)
        .map(|i| {
            let (x, y) = ((i % 2) as f32, (i / 2) as f32);
            (i, glam::Vec2::new((x + 0.5) / 2.0, 1.0 - (y + 0.5) / 2.0))
        })
        .collect();
    let srgb = |c: u8| glint::scene::image::srgb_to_linear(c as f32 / 255.0);
    let mut cpu = Vec::new();
    for &(i, uv) in &centres {
        let m = material_at(&textures, &material, both_sets(uv));
        let c = COLOR_TEXELS[i];
        let want = Vec3::new(0.5 * srgb(c[0]), srgb(c[1]), 0.25 * srgb(c[2]));
        assert!(
            (Vec3::from(m.albedo) - want).abs().max_element() < 1e-6,
            "texel {i}: colour {:?}, want {want}",
            m.albedo
        );
        let [_, g, b] = METALLIC_ROUGHNESS_TEXELS[i];
        let roughness = 0.8 * (g as f32 / 255.0);
        assert!(
            (m.alpha - roughness * roughness).abs() < 1e-6,
            "texel {i}: alpha {}",
            m.alpha
        );
        assert!(
            (m.metallic - 0.5 * (b as f32 / 255.0)).abs() < 1e-6,
            "texel {i}: metallic {}",
            m.metallic
        );
        let transmission = 0.5 * (c[0] as f32 / 255.0);
        assert!(
            (m.transmission - transmission).abs() < 1e-6,
            "texel {i}: transmission {}",
            m.transmission
        );
        cpu.push([m.albedo[0], m.albedo[1], m.albedo[2], m.alpha]);
        cpu.push([m.metallic, m.transmission, 0.0, 0.0]);
    }
    let Some(ctx) = common::gpu() else { return };
    let mut probed = scene.clone();
    probed.triangle_uvs = centres
        .iter()
        .map(|(_, uv)| glint::kernel::types::TriangleUvs {
            uv0: uv.to_array(),
            ..Default::default()
        })
        .collect();
    let params = common::probe::ProbeParams {
        count: cpu.len() as u32,
        seed: index,
        ..Default::default()
    };
    let gpu = common::probe::run_probe(ctx, "probe_material_at", params, &probed);
    for (k, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
        for (a, b) in c.iter().zip(g) {
            assert!((a - b).abs() <= 1e-6, "entry {k}: CPU {c:?}, GPU {g:?}");
        }
    }
}

/// Embedded images that cannot be used are errors naming the file and the element.
#[test]
fn bad_embedded_images_name_their_element() {
    let material =
        || serde_json::json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}});
    let with = |images: &[Vec<u8>], edit: &dyn Fn(&mut serde_json::Value)| {
        let bytes = glb(material(), images, |g| {
            g["textures"] = serde_json::json!([{"source": 0}]);
            edit(g);
        });
        load_glb(&bytes).expect_err("the file should be refused")
    };
    let mut cut = png(COLOR_TEXELS);
    cut.truncate(40);
    for (message, needles) in [
        (
            with(&[cut], &|_| {}),
            &["t.glb", "images[0]", "cannot decode"][..],
        ),
        (
            with(&[b"GIF89a\x01\x00\x01\x00\x00\x00\x00;".to_vec()], &|_| {}),
            &["t.glb", "images[0]", "Gif image", "PNG and JPEG"][..],
        ),
        (
            with(&[png(COLOR_TEXELS)], &|g| {
                g["images"][0]["bufferView"] = 5.into()
            }),
            &[
                "t.glb",
                "images[0].bufferView",
                "buffer view 5 does not exist",
            ][..],
        ),
        (
            with(&[], &|g| {
                g["images"] = serde_json::json!([{"uri": "data:image/png;base64,@@@"}])
            }),
            &["t.glb", "images[0]", "base64"][..],
        ),
    ] {
        for needle in needles {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
        assert!(!message.contains('\n'), "{message:?}");
    }
}

/// A texture on TEXCOORD_2 (or later), and a normal map on TEXCOORD_1 (its tangents follow
/// TEXCOORD_0), are left out with a warning.
#[test]
fn a_texture_on_the_third_coordinate_set_is_a_warning() {
    let material = serde_json::json!({"pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0, "texCoord": 2}
    }, "normalTexture": {"index": 0, "texCoord": 1}});
    let (mut json, bin) = triangle_gltf(material);
    json["images"] = serde_json::json!([{"uri": "missing.png"}]);
    json["textures"] = serde_json::json!([{"source": 0}]);
    let warnings = render_warnings(&json, &bin);
    for needle in [
        "baseColorTexture: on TEXCOORD_2",
        "normalTexture: on TEXCOORD_1",
    ] {
        assert!(
            warnings.iter().any(|w| w.contains(needle)),
            "{needle}: {warnings:?}"
        );
    }
}

/// A square of two triangles facing a camera 5 in front of it, which sees 2.5 units across
/// in 32² pixels, black behind it, no scattering: a pixel is what the square emits. Its
/// emissive texture (COLOR_TEXELS, nearest) is on TEXCOORD_1, which lays the image over the
/// square upright; TEXCOORD_0 puts every vertex on one texel (the top left).
fn texcoord1_square(dir: &std::path::Path) -> glint::kernel::KernelScene {
    use base64::Engine as _;
    let corners = [[-1.0f32, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    let mut bin: Vec<u8> = Vec::new();
    for [x, y] in corners {
        bin.extend([x, y, 0.0].iter().flat_map(|f| f.to_le_bytes()));
    }
    for _ in corners {
        bin.extend([0.1f32, 0.1].iter().flat_map(|f| f.to_le_bytes()));
    }
    // glTF's v points down: the image's top row at the square's top.
    for [x, y] in corners {
        bin.extend(
            [(x + 1.0) / 2.0, (1.0 - y) / 2.0]
                .iter()
                .flat_map(|f| f.to_le_bytes()),
        );
    }
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png(COLOR_TEXELS))
    );
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2},
            "indices": 3,
            "material": 0
        }]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
            "emissiveFactor": [1, 1, 1],
            "emissiveTexture": {"index": 0, "texCoord": 1}
        }],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728}],
        "images": [{"uri": uri}],
        "buffers": [{"uri": "square.bin", "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 32},
            {"buffer": 0, "byteOffset": 80, "byteLength": 32},
            {"buffer": 0, "byteOffset": 112, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ]
    });
    std::fs::write(dir.join("square.bin"), &bin).unwrap();
    std::fs::write(dir.join("t.gltf"), serde_json::to_vec(&json).unwrap()).unwrap();
    let vfov = 2.0 * (1.25f32 / 5.0).atan().to_degrees();
    let text = format!(
        "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         vfov = {vfov}\n\n[render]\nwidth = 32\nheight = 32\nspp = 4\nmax_bounces = 0\n\
         background = [0.0, 0.0, 0.0]\n\n[[meshes]]\nfile = \"t.gltf\"\n"
    );
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    Scene::load(&dir.join("scene.toml"))
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel_scene()
}

/// A texture on TEXCOORD_1 reads the second set: its descriptor says so, the set is uploaded
/// (v flipped as set 0 is), and the square shows each texel in its quadrant (the first set
/// would show the top-left texel everywhere), on the CPU and on both GPU traversals, which
/// agree.
#[test]
fn a_texture_on_texcoord_1_reads_the_second_set_on_both_devices() {
    use glint::cpu::integrator::renderer::CpuRenderer;
    use glint::gpu::{GpuRenderer, Traversal};
    use glint::render::render_image;
    let dir = tempfile::tempdir().unwrap();
    let scene = texcoord1_square(dir.path());
    let texture = scene.textures[scene.materials[0].emission_texture as usize];
    assert_eq!(texture.uv_set, 1);
    assert!(glint::kernel::variant::KernelFeatures::of(&scene).texcoord1);
    assert_eq!(scene.triangle_uvs1.len(), 2);
    assert_eq!(scene.triangle_uvs1[0].uv1, [1.0, 0.0]);
    assert_eq!(scene.triangle_uvs[0].uv1, [0.1, 0.9]);
    let mut images = vec![(
        "cpu",
        render_image(&mut CpuRenderer::new(&scene), 4, 4).unwrap(),
    )];
    if let Some(ctx) = common::gpu() {
        let mut software = GpuRenderer::with_traversal(ctx, &scene, Traversal::Software).unwrap();
        images.push(("gpu software", render_image(&mut software, 4, 4).unwrap()));
    }
    if let Some(ctx) = common::gpu_with_ray_queries() {
        let mut hardware = GpuRenderer::with_traversal(ctx, &scene, Traversal::Hardware).unwrap();
        images.push(("gpu hardware", render_image(&mut hardware, 4, 4).unwrap()));
    }
    let srgb = |c: u8| glint::scene::image::srgb_to_linear(c as f32 / 255.0);
    // Quadrant centres, top-left first as the texels.
    let pixels = [(9u32, 9u32), (22, 9), (9, 22), (22, 22)];
    for (device, image) in &images {
        for (i, (x, y)) in pixels.into_iter().enumerate() {
            let p = image.pixels[(y * image.width + x) as usize];
            let want = COLOR_TEXELS[i].map(srgb);
            for c in 0..3 {
                assert!(
                    (p[c] - want[c]).abs() < 1e-5,
                    "{device}: quadrant {i} is {p:?}, want {want:?}"
                );
            }
        }
        let worst = images[0]
            .1
            .pixels
            .iter()
            .flatten()
            .zip(image.pixels.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(worst < 1e-5, "{device}: differs from the CPU by {worst}");
    }
}

/// A texture's sampler (wrap modes, magnification filter) and KHR_texture_transform reach its
/// descriptor, the transform converted to glint's v-up coordinates: for glint's (u, v), the
/// descriptor's map gives what the extension's T·R·S (written out here independently, the
/// rotation counterclockwise with v down as its text says and TextureTransformTest.gltf
/// checks, tests/suite/gltf_samples.rs) gives for glTF's (u, 1 − v), with v flipped back.
#[test]
fn samplers_and_texture_transforms_reach_the_descriptor() {
    use glint::kernel::types::{TEXTURE_NEAREST, TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_MIRROR};
    let (offset, rotation, scale) = ([0.25f32, -0.5], 0.5f32, [2.0f32, 3.0]);
    let material = serde_json::json!({"pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
            "offset": offset, "rotation": rotation, "scale": scale
        }}}
    }});
    let bytes = glb(material, &[png(COLOR_TEXELS)], |g| {
        g["textures"] = serde_json::json!([{"source": 0, "sampler": 0}]);
        g["samplers"] = serde_json::json!([{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728}]);
        g["extensionsUsed"] = serde_json::json!(["KHR_texture_transform"]);
        g["extensionsRequired"] = serde_json::json!(["KHR_texture_transform"]);
    });
    let scene = load_glb(&bytes).unwrap_or_else(|e| panic!("{e}"));
    let index = scene.triangles[0].material as usize;
    let scene = scene.kernel_scene();
    let t = scene.textures[scene.materials[index].color_texture as usize];
    assert_eq!(
        t.sampling,
        TEXTURE_WRAP_CLAMP | (TEXTURE_WRAP_MIRROR << 8) | TEXTURE_NEAREST
    );
    let (s, c) = rotation.sin_cos();
    let translation =
        glam::Mat3::from_cols_array(&[1., 0., 0., 0., 1., 0., offset[0], offset[1], 1.]);
    let rotate = glam::Mat3::from_cols_array(&[c, -s, 0., s, c, 0., 0., 0., 1.]);
    let scaling = glam::Mat3::from_cols_array(&[scale[0], 0., 0., 0., scale[1], 0., 0., 0., 1.]);
    let matrix = translation * rotate * scaling;
    for uv in [[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0], [0.3, 0.7]] {
        let gltf = matrix * Vec3::new(uv[0], 1.0 - uv[1], 1.0);
        let want = glam::Vec2::new(gltf.x, 1.0 - gltf.y);
        let got = glint::cpu::textures::texture::transformed_uv(&t, glam::Vec2::from(uv));
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "at {uv:?}: {got} against {want}"
        );
    }
}

/// A sampler's wrap mode that is not one of glTF's is an error naming the sampler.
#[test]
fn an_unknown_wrap_mode_is_an_error() {
    let material = serde_json::json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}});
    let bytes = glb(material, &[png(COLOR_TEXELS)], |g| {
        g["textures"] = serde_json::json!([{"source": 0, "sampler": 0}]);
        g["samplers"] = serde_json::json!([{"wrapT": 1234}]);
    });
    let message = load_glb(&bytes).expect_err("the file should be refused");
    for needle in ["t.glb", "samplers[0].wrapT", "wrap mode"] {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}

/// glTF's alphaMode, alphaCutoff (default 0.5) and baseColorFactor's alpha become the
/// material's alpha, and reach the kernel's material as its mode, opacity and cutoff.
#[test]
fn alpha_mode_cutoff_and_opacity_map_onto_the_material() {
    use glint::kernel::types::{ALPHA_BLEND, ALPHA_MASK, ALPHA_OPAQUE};
    use glint::scene::{Alpha, AlphaMode};
    for (material, want, kernel) in [
        (serde_json::json!({}), Alpha::OPAQUE, (ALPHA_OPAQUE, 0.5)),
        (
            // OPAQUE keeps the opacity it is given; the kernel never reads it.
            serde_json::json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.25]}}),
            Alpha {
                mode: AlphaMode::Opaque,
                opacity: 0.25,
            },
            (ALPHA_OPAQUE, 0.5),
        ),
        (
            serde_json::json!({"alphaMode": "MASK"}),
            Alpha {
                mode: AlphaMode::Mask { cutoff: 0.5 },
                opacity: 1.0,
            },
            (ALPHA_MASK, 0.5),
        ),
        (
            serde_json::json!({"alphaMode": "MASK", "alphaCutoff": 0.3,
                "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.6]}}),
            Alpha {
                mode: AlphaMode::Mask { cutoff: 0.3 },
                opacity: 0.6,
            },
            (ALPHA_MASK, 0.3),
        ),
        (
            serde_json::json!({"alphaMode": "BLEND",
                "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}}),
            Alpha {
                mode: AlphaMode::Blend,
                opacity: 0.3,
            },
            (ALPHA_BLEND, 0.5),
        ),
    ] {
        let (json, bin) = triangle_gltf(material.clone());
        let scene = load(&json, &bin).unwrap_or_else(|e| panic!("{e}"));
        let index = scene.triangles[0].material as usize;
        assert_eq!(scene.materials[index].alpha, want, "{material}");
        let m = scene.kernel_scene().materials[index];
        assert_eq!(
            (m.alpha_mode, m.alpha_cutoff),
            kernel,
            "{material}: kernel mode and cutoff"
        );
        assert_eq!(m.opacity, want.opacity, "{material}: kernel opacity");
    }
}

/// An alpha cutoff or a base colour alpha outside [0, 1], or an unknown alpha mode, is an
/// error naming the file and the field; `glint render` exits 2 with it.
#[test]
fn alpha_out_of_range_is_an_error_naming_the_field() {
    for (material, needles) in [
        (
            serde_json::json!({"alphaMode": "MASK", "alphaCutoff": 1.5}),
            &["materials[0].alphaCutoff", "must be in [0, 1]", "1.5"][..],
        ),
        (
            serde_json::json!({"alphaMode": "MASK", "alphaCutoff": -0.25}),
            &["materials[0].alphaCutoff", "-0.25"][..],
        ),
        (
            serde_json::json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1.2]}}),
            &[
                "materials[0].pbrMetallicRoughness.baseColorFactor",
                "alpha",
                "1.2",
            ][..],
        ),
        (
            serde_json::json!({"alphaMode": "TRANSLUCENT"}),
            &["materials[0].alphaMode", "not a glTF alpha mode"][..],
        ),
    ] {
        assert_material_refused(material, needles);
    }
    let (json, bin) = triangle_gltf(serde_json::json!({"alphaMode": "MASK", "alphaCutoff": 2}));
    let dir = write(&json, &bin);
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
    common::assert_refused(&run, &out, &["t.gltf", "materials[0].alphaCutoff"]);
}

/// A 2×2 RGBA PNG with these texels, top row first.
fn rgba_png(texels: [[u8; 4]; 4]) -> Vec<u8> {
    let image = image::RgbaImage::from_fn(2, 2, |x, y| image::Rgba(texels[(y * 2 + x) as usize]));
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

/// The base colour texture's alpha is kept (linear: glTF never sRGB-encodes alpha) and the
/// kernel's alpha at each texel centre is baseColorFactor.a × the texel's alpha, where the
/// colour is sRGB-decoded as before. An RGB texture's alpha is 1.
#[test]
fn the_base_color_textures_alpha_is_kept_linear() {
    use glint::cpu::textures::texture::{both_sets, texture_alpha, Textures};
    let texels = [
        [255, 0, 0, 0],
        [0, 255, 0, 64],
        [0, 0, 255, 128],
        [9, 9, 9, 255],
    ];
    for (image, alphas) in [
        (rgba_png(texels), texels.map(|t| t[3] as f32 / 255.0)),
        (png(COLOR_TEXELS), [1.0; 4]),
    ] {
        let material = serde_json::json!({"alphaMode": "BLEND", "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 1.0, 1.0, 0.5],
            "baseColorTexture": {"index": 0}
        }});
        let bytes = glb(material, &[image], |g| {
            g["textures"] = serde_json::json!([{"source": 0}]);
        });
        let scene = load_glb(&bytes).unwrap_or_else(|e| panic!("{e}"));
        let index = scene.triangles[0].material as usize;
        let scene = scene.kernel_scene();
        let m = scene.materials[index];
        let textures = Textures {
            descriptors: &scene.textures,
            texels: &scene.texels,
        };
        for (i, want) in alphas.iter().enumerate() {
            let (x, y) = ((i % 2) as f32, (i / 2) as f32);
            let uv = glam::Vec2::new((x + 0.5) / 2.0, 1.0 - (y + 0.5) / 2.0);
            let got = m.opacity * texture_alpha(&textures, m.color_texture, both_sets(uv));
            assert!(
                (got - 0.5 * want).abs() < 1e-6,
                "texel {i}: alpha {got}, want {}",
                0.5 * want
            );
        }
    }
}

/// KHR_materials_unlit: the surface emits its base colour and reflects nothing; the file's
/// other factors (metal, roughness, emission) do not apply; the extension is fully read (no
/// warning).
#[test]
fn unlit_materials_emit_their_base_colour() {
    let material = serde_json::json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.2, 0.4, 0.6, 1.0],
            "metallicFactor": 1.0,
            "roughnessFactor": 0.3
        },
        "emissiveFactor": [1.0, 1.0, 1.0],
        "extensions": {"KHR_materials_unlit": {}}
    });
    let m = loaded_material(material.clone());
    assert_eq!(m.kind, glint::scene::MaterialKind::Unlit);
    assert_eq!(m.color, glam::Vec3::ZERO);
    assert_eq!(m.emitted_radiance, glam::Vec3::new(0.2, 0.4, 0.6));
    assert_eq!(m.emission_texture, None);
    let (mut json, bin) = triangle_gltf(material);
    json["extensionsUsed"] = serde_json::json!(["KHR_materials_unlit"]);
    json["extensionsRequired"] = serde_json::json!(["KHR_materials_unlit"]);
    assert_eq!(render_warnings(&json, &bin), Vec::<String>::new());
}

/// KHR_materials_clearcoat and KHR_materials_sheen become the pbr material's layers, with
/// their textures (through KHR_texture_transform like the others): the coat's red channel, the
/// coat roughness's green, the sheen colour's RGB (sRGB) and the sheen roughness's alpha, each
/// in the first channel the kernel reads (the colour in all three).
#[test]
fn clearcoat_and_sheen_become_the_pbr_materials_layers() {
    let material = serde_json::json!({
        "pbrMetallicRoughness": {"roughnessFactor": 0.5, "metallicFactor": 0.0},
        "extensions": {
            "KHR_materials_clearcoat": {
                "clearcoatFactor": 0.8,
                "clearcoatTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                    "offset": [0.5, 0.0]
                }}},
                "clearcoatRoughnessFactor": 0.3,
                "clearcoatRoughnessTexture": {"index": 1}
            },
            "KHR_materials_sheen": {
                "sheenColorFactor": [0.5, 0.25, 1.0],
                "sheenColorTexture": {"index": 0},
                "sheenRoughnessFactor": 0.6,
                "sheenRoughnessTexture": {"index": 2}
            }
        }
    });
    let rgba = rgba_png([[0, 0, 0, 255], [0, 0, 0, 128], [0, 0, 0, 51], [0, 0, 0, 0]]);
    let bytes = glb(
        material,
        &[png(COLOR_TEXELS), png(METALLIC_ROUGHNESS_TEXELS), rgba],
        |g| {
            g["textures"] = serde_json::json!([{"source": 0}, {"source": 1}, {"source": 2}]);
            g["extensionsUsed"] = serde_json::json!([
                "KHR_materials_clearcoat",
                "KHR_materials_sheen",
                "KHR_texture_transform"
            ]);
            g["extensionsRequired"] =
                serde_json::json!(["KHR_materials_clearcoat", "KHR_materials_sheen"]);
        },
    );
    let scene = load_glb(&bytes).unwrap_or_else(|e| panic!("{e}"));
    let index = scene.triangles[0].material as usize;
    let MaterialKind::Pbr { layers, .. } = scene.materials[index].kind else {
        panic!("{:?}", scene.materials[index].kind)
    };
    assert_eq!((layers.clearcoat, layers.clearcoat_roughness), (0.8, 0.3));
    assert_eq!(
        (layers.sheen_color, layers.sheen_roughness),
        (Vec3::new(0.5, 0.25, 1.0), 0.6)
    );
    assert_eq!(layers.clearcoat_normal_texture, None);
    let k = scene.kernel_scene();
    let m = k.materials[index];
    assert_eq!((m.clearcoat, m.sheen_roughness), (0.8, 0.6));
    assert!((m.clearcoat_alpha - 0.09).abs() < 1e-7);
    assert_eq!(m.sheen_color, [0.5, 0.25, 1.0]);
    // The first texel each texture holds is the image's bottom-left (texels[2]).
    let first = |t: u32| k.texels[k.textures[t as usize].first_texel as usize];
    assert_eq!(first(m.clearcoat_texture)[0], 0.0, "red of (0, 0, 255)");
    assert_eq!(
        first(m.clearcoat_roughness_texture)[0],
        0.0,
        "green of (9, 0, 64)"
    );
    assert!((first(m.sheen_roughness_texture)[0] - 51.0 / 255.0).abs() < 1e-6);
    assert_eq!(
        first(m.sheen_color_texture)[2],
        1.0,
        "blue of (0, 0, 255), sRGB"
    );
    // The transform reached the coat's texture and no other.
    let transform = |t: u32| k.textures[t as usize].transform_u;
    assert_eq!(transform(m.clearcoat_texture), [1.0, 0.0, 0.5]);
    assert_eq!(transform(m.sheen_color_texture), [1.0, 0.0, 0.0]);
}

/// Both extensions are read: a file that uses (and requires) them renders without a warning
/// about them.
#[test]
fn clearcoat_and_sheen_render_without_a_warning() {
    let (mut json, bin) = triangle_gltf(serde_json::json!({"extensions": {
        "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.2},
        "KHR_materials_sheen": {"sheenColorFactor": [1.0, 0.5, 0.5], "sheenRoughnessFactor": 0.5}
    }}));
    json["extensionsUsed"] = serde_json::json!(["KHR_materials_clearcoat", "KHR_materials_sheen"]);
    json["extensionsRequired"] = json["extensionsUsed"].clone();
    let warnings = render_warnings(&json, &bin);
    assert!(
        !warnings
            .iter()
            .any(|w| w.contains("clearcoat") || w.contains("sheen")),
        "{warnings:?}"
    );
}

/// Out-of-range or malformed clearcoat and sheen values are errors naming the material and the
/// field.
#[test]
fn bad_clearcoat_and_sheen_values_are_named_errors() {
    for (extension, needles) in [
        (
            serde_json::json!({"KHR_materials_clearcoat": {"clearcoatFactor": 1.5}}),
            &["material0", "clearcoatFactor must be in [0, 1]", "1.5"][..],
        ),
        (
            serde_json::json!({"KHR_materials_clearcoat": {"clearcoatRoughnessFactor": -0.5}}),
            &["material0", "clearcoatRoughnessFactor must be in [0, 1]"][..],
        ),
        (
            serde_json::json!({"KHR_materials_clearcoat": {"clearcoatFactor": "thick"}}),
            &["materials[0].extensions.KHR_materials_clearcoat"][..],
        ),
        (
            serde_json::json!({"KHR_materials_sheen": {"sheenColorFactor": [2.0, 0.0, 0.0]}}),
            &["material0", "sheenColorFactor must be in [0, 1]"][..],
        ),
        (
            serde_json::json!({"KHR_materials_sheen": {"sheenRoughnessFactor": 3.0}}),
            &["material0", "sheenRoughnessFactor must be in [0, 1]", "3"][..],
        ),
        (
            serde_json::json!({"KHR_materials_sheen": {
                "sheenColorFactor": [1.0, 1.0, 1.0],
                "sheenColorTexture": {"index": 7}
            }}),
            &["materials[0].extensions.KHR_materials_sheen"][..],
        ),
    ] {
        assert_material_refused(serde_json::json!({ "extensions": extension }), needles);
    }
}

/// One table (`GLTF_EXTENSIONS`) decides what a file may require: a file that requires every
/// extension glint reads loads, and the only warning about extensions names those read in
/// part. (Blender's exporter requires KHR_lights_punctual whenever the scene has a lamp; an
/// earlier second list left it out and refused every such file.)
#[test]
fn a_file_may_require_every_extension_glint_reads() {
    use glint::scene::mesh::{ExtensionSupport, GLTF_EXTENSIONS};
    let (mut json, bin) = triangle_gltf(serde_json::json!({}));
    let every: Vec<&str> = GLTF_EXTENSIONS.iter().map(|&(name, _)| name).collect();
    assert!(every.contains(&"KHR_lights_punctual"));
    json["extensionsUsed"] = serde_json::json!(every);
    json["extensionsRequired"] = serde_json::json!(every);
    let warnings = render_warnings(&json, &bin);
    let in_part: Vec<&str> = GLTF_EXTENSIONS
        .iter()
        .filter(|(_, support)| matches!(support, ExtensionSupport::InPart(_)))
        .map(|&(name, _)| name)
        .collect();
    let about_extensions: Vec<&String> = warnings
        .iter()
        .filter(|w| w.contains("glTF extensions"))
        .collect();
    assert_eq!(about_extensions.len(), 1, "{warnings:?}");
    for name in every {
        assert_eq!(
            about_extensions[0].contains(name),
            in_part.contains(&name),
            "{name}: {warnings:?}"
        );
    }
}
