//! OBJ `.mtl` files with the PBR extension, as Blender's exporter writes them: `Pr`, `Pm`,
//! `map_Pr`, `map_Pm`, `map_Ke`, `norm`/`map_Bump -bm`, and the statements' options, become
//! glint's `pbr` material and its maps; bad values are refused naming the material and field.

use crate::common;
use glint::scene::{MaterialKind, Scene};
use std::path::Path;

/// A unit quad with texture coordinates whose material is `usemtl m` from `mtl`, in a scene
/// file `scene.toml` in `dir` that names no material (the file's own is used).
fn write_files(dir: &Path, mtl: &str) {
    let obj = "mtllib q.mtl\nv 1 -1 0\nv -1 -1 0\nv -1 1 0\nv 1 1 0\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    std::fs::write(dir.join("q.obj"), obj).unwrap();
    std::fs::write(dir.join("q.mtl"), mtl).unwrap();
    let scene = format!(
        "{}\n[[meshes]]\nfile = \"q.obj\"\n",
        common::MESH_SCENE_HEADER
    );
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
}

/// The scene of [`write_files`], loaded, with the images the tests name beside it:
/// `rough.png` (2×1, grey 64 and 192), `metal.png` (1×1, 255), and mid-grey `glow.png`,
/// `my normals.png` and `other.png`.
fn load(mtl: &str) -> (Scene, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    write_files(dir.path(), mtl);
    write_grey_png(&dir.path().join("rough.png"), 2, 1, [64, 192]);
    write_grey_png(&dir.path().join("metal.png"), 1, 1, [255]);
    for name in ["glow.png", "my normals.png", "other.png"] {
        write_grey_png(&dir.path().join(name), 1, 1, [128]);
    }
    let scene = Scene::load(&dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    (scene, dir)
}

fn write_grey_png(path: &Path, width: u32, height: u32, values: impl AsRef<[u8]>) {
    let values = values.as_ref().to_vec();
    image::GrayImage::from_fn(width, height, |x, y| {
        image::Luma([values[(y * width + x) as usize]])
    })
    .save(path)
    .unwrap();
}

fn the_material(scene: &Scene) -> &glint::scene::Material {
    scene
        .materials
        .iter()
        .find(|m| m.name == "q.obj/m")
        .unwrap()
}

#[test]
fn blenders_pbr_statements_make_a_pbr_material() {
    let (scene, _dir) = load("newmtl m\nKd 0.8 0.4 0.2\nNs 250\nNi 1.45\nPr 0.3\nPm 0.75\n");
    let m = the_material(&scene);
    assert_eq!(m.color, glam::Vec3::new(0.8, 0.4, 0.2));
    match m.kind {
        MaterialKind::Pbr {
            roughness,
            metallic,
            ior,
            ..
        } => {
            assert_eq!((roughness, metallic, ior), (0.3, 0.75, 1.45));
        }
        ref k => panic!("{k:?}"),
    }
    // Without Pr, the roughness comes from Ns as Blender's importer derives it.
    let (scene, _dir) = load("newmtl m\nKd 0.5 0.5 0.5\nNs 250\nPm 1\n");
    match the_material(&scene).kind {
        MaterialKind::Pbr { roughness, .. } => assert!((roughness - 0.5).abs() < 1e-6),
        ref k => panic!("{k:?}"),
    }
    // A plain .mtl stays what it was: diffuse Kd.
    let (scene, _dir) = load("newmtl m\nKd 0.5 0.5 0.5\nNs 250\n");
    assert_eq!(the_material(&scene).kind, MaterialKind::Diffuse);
}

#[test]
fn roughness_and_metallic_maps_merge_into_one_texture() {
    // The roughness image is 2×1 (64 and 192 of 255), the metallic one 1×1 (255): merged at
    // the roughness image's size, x the roughness and y the metallic factor.
    let (scene, _dir) = load(
        "newmtl m\nKd 1 1 1\nPr 1\nPm 1\nmap_Pr -s 1 1 1 rough.png\nmap_Pm -clamp on metal.png\n",
    );
    let texture = the_material(&scene).roughness_texture.expect("a texture");
    let descriptor = scene.textures.descriptors[texture as usize];
    assert_eq!((descriptor.width, descriptor.height), (2, 1));
    let first = descriptor.first_texel as usize;
    let texels = &scene.textures.texels[first..first + 2];
    for (texel, grey) in texels.iter().zip([64.0, 192.0]) {
        assert!((texel[0] - grey / 255.0).abs() < 1e-6, "{texels:?}");
        assert_eq!(texel[1], 1.0);
    }
    // Only a metallic map: roughness 1 in x.
    let (scene, _dir) = load("newmtl m\nPm 1\nmap_Pm metal.png\n");
    let texture = the_material(&scene).roughness_texture.unwrap();
    let first = scene.textures.descriptors[texture as usize].first_texel as usize;
    assert_eq!(scene.textures.texels[first][..2], [1.0, 1.0]);
}

#[test]
fn emission_and_normal_maps_are_read_with_their_options() {
    // A map file name with a space, after options with one and three arguments.
    let (scene, dir) = load(
        "newmtl m\nKd 1 1 1\nPr 0.5\nmap_Ke glow.png\nmap_Bump -bm 0.25 -s 2 2 1 my normals.png\n",
    );
    let m = the_material(&scene);
    // Ke absent with map_Ke: the map is the emission.
    assert_eq!(m.emitted_radiance, glam::Vec3::ONE);
    assert!(m.emission_texture.is_some());
    let (_, scale) = m.normal_texture.expect("a normal map");
    assert_eq!(scale, 0.25);
    // `norm` (the PBR extension's statement) wins over map_Bump.
    std::fs::write(
        dir.path().join("q.mtl"),
        "newmtl m\nPr 0.5\nnorm -bm 2 my normals.png\nmap_Bump other.png\n",
    )
    .unwrap();
    let scene = Scene::load(&dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(the_material(&scene).normal_texture.unwrap().1, 2.0);
}

/// `d` < 1 (or `Tr` > 0, Tr = 1 − d) is blended opacity on any material kind; Blender's
/// `d 1.000000` on opaque materials leaves them opaque.
#[test]
fn dissolve_and_transparency_are_blended_opacity() {
    use glint::scene::{Alpha, AlphaMode, MaterialKind};
    let blend = |opacity: f32| Alpha {
        mode: AlphaMode::Blend,
        opacity,
    };
    for (mtl, kind, alpha) in [
        (
            "Kd 0.5 0.5 0.5\nd 0.25\n",
            MaterialKind::Diffuse,
            blend(0.25),
        ),
        (
            "Kd 0.5 0.5 0.5\nTr 0.75\n",
            MaterialKind::Diffuse,
            blend(0.25),
        ),
        (
            "Kd 0.5 0.5 0.5\nd 1.000000\n",
            MaterialKind::Diffuse,
            Alpha::OPAQUE,
        ),
        (
            "Kd 0.5 0.5 0.5\nTr 0\n",
            MaterialKind::Diffuse,
            Alpha::OPAQUE,
        ),
        (
            "Ks 0.9 0.9 0.9\nillum 3\nd 0.5\n",
            MaterialKind::Specular,
            blend(0.5),
        ),
    ] {
        let (scene, _dir) = load(&format!("newmtl m\n{mtl}"));
        let m = the_material(&scene);
        assert_eq!((m.kind, m.alpha), (kind, alpha), "{mtl}");
    }
    // Blender's PBR statements with d.
    let (scene, _dir) = load("newmtl m\nKd 1 1 1\nPr 0.5\nd 0.5\n");
    let m = the_material(&scene);
    assert!(matches!(m.kind, MaterialKind::Pbr { .. }), "{:?}", m.kind);
    assert_eq!(m.alpha, blend(0.5));
}

/// `map_d`'s first channel becomes the colour texture's alpha (the material blended), merged
/// with `map_Kd` where the material has one (at its size, the opacity image resampled
/// nearest) and white where it has none (the colour stays `Kd`).
#[test]
fn an_opacity_map_is_the_colour_textures_alpha() {
    use glint::scene::AlphaMode;
    let srgb = |c: f32| glint::scene::image::srgb_to_linear(c / 255.0);
    for (mtl, color, texels) in [
        (
            "Kd 0.5 0.5 0.5\nmap_d rough.png\n",
            0.5,
            vec![
                [1.0, 1.0, 1.0, 64.0 / 255.0],
                [1.0, 1.0, 1.0, 192.0 / 255.0],
            ],
        ),
        (
            "Kd 0.5 0.5 0.5\nmap_Kd glow.png\nmap_d -imfchan m rough.png\n",
            1.0,
            vec![[srgb(128.0), srgb(128.0), srgb(128.0), 64.0 / 255.0]],
        ),
    ] {
        let (scene, _dir) = load(&format!("newmtl m\n{mtl}"));
        let m = the_material(&scene);
        assert_eq!(m.alpha.mode, AlphaMode::Blend, "{mtl}");
        assert_eq!(m.alpha.opacity, 1.0, "{mtl}");
        assert_eq!(m.color, glam::Vec3::splat(color), "{mtl}");
        let t = scene.textures.descriptors[m.color_texture.expect("a colour texture") as usize];
        let got = &scene.textures.texels[t.first_texel as usize..][..(t.width * t.height) as usize];
        assert_eq!(got.len(), texels.len(), "{mtl}");
        for (g, w) in got.iter().zip(&texels) {
            for (a, b) in g.iter().zip(w) {
                assert!(
                    (a - b).abs() < 1e-6,
                    "{mtl}: texels {got:?}, want {texels:?}"
                );
            }
        }
    }
}

/// Blender's exporter names map_Kd's RGBA image in map_d too: the image's alpha channel, not
/// its first, is then the opacity.
#[test]
fn an_rgba_opacity_map_gives_its_alpha() {
    let dir = tempfile::tempdir().unwrap();
    write_files(
        dir.path(),
        "newmtl m\nKd 0.8 0.8 0.8\nmap_Kd leaf.png\nmap_d leaf.png\n",
    );
    image::RgbaImage::from_fn(1, 1, |_, _| image::Rgba([255, 0, 0, 51]))
        .save(dir.path().join("leaf.png"))
        .unwrap();
    let scene = Scene::load(&dir.path().join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    let m = the_material(&scene);
    let t = scene.textures.descriptors[m.color_texture.expect("a colour texture") as usize];
    let texel = scene.textures.texels[t.first_texel as usize];
    assert_eq!(texel, [1.0, 0.0, 0.0, 0.2]);
}

#[test]
fn bad_pbr_values_are_refused_naming_material_and_statement() {
    for (mtl, needles) in [
        ("newmtl m\nPr 1.5\n", vec!["\"m\"", "Pr", "[0, 1]", "1.5"]),
        ("newmtl m\nPm -0.5\n", vec!["\"m\"", "Pm", "[0, 1]"]),
        ("newmtl m\nPr rough\n", vec!["\"m\"", "Pr", "not a number"]),
        (
            "newmtl m\nd 1.5\n",
            vec!["\"m\"", "d must be in [0, 1]", "1.5"],
        ),
        ("newmtl m\nTr -0.5\n", vec!["\"m\"", "Tr must be in [0, 1]"]),
        (
            "newmtl m\nPr 0.5\nmap_Pr -bm 1\n",
            vec!["\"m\"", "map_Pr", "no image"],
        ),
        (
            "newmtl m\nPr 0.5\nmap_Pr missing.png\n",
            vec!["\"m\"", "missing.png"],
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        write_files(dir.path(), mtl);
        let out = dir.path().join("out.png");
        let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
        let mut needles = needles;
        needles.push("meshes[0].file");
        common::assert_refused(&run, &out, &needles);
    }
}

#[test]
fn unread_pbr_statements_are_named_in_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    write_files(dir.path(), "newmtl m\nPr 0.5\nPc 1\nPcr 0.1\nPs 0.3\n");
    let out = dir.path().join("out.png");
    let run = common::run_render("--cpu", &dir.path().join("scene.toml"), &out);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.contains("Pc")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    for needle in ["q.obj", "\"m\"", "Ps", "Pc", "Pcr"] {
        assert!(warnings[0].contains(needle), "{stderr}");
    }
}
