//! Every class of bad scene gets an error that names the file, the line and the field: each
//! checked through the loader, message and all (the CLI's exit code 2 for bad input is in
//! tests/suite/cli.rs and tests/suite/hardening_io.rs).

use glint::scene::{Scene, SceneError};
use std::path::Path;

const GOOD: &str = r#"[camera]
eye = [0.0, 1.0, -5.0]
target = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
vfov = 40.0

[render]
width = 64
height = 48
spp = 4
max_bounces = 4

[materials.white]
type = "diffuse"
color = [0.7, 0.7, 0.7]

[materials.lamp]
type = "diffuse"
color = [0.0, 0.0, 0.0]
emission = [1.0, 1.0, 1.0]
strength = 5

[[spheres]]
center = [0.0, 1.0, 0.0]
radius = 1.0
material = "white"

[[quads]]
corner = [-5.0, 0.0, -5.0]
u = [10.0, 0.0, 0.0]
v = [0.0, 0.0, 10.0]
material = "lamp"
"#;

fn parse(text: &str) -> Result<Scene, SceneError> {
    Scene::parse(text, Path::new("scenes/bad.toml"))
}

/// `GOOD` with the first occurrence of `from` replaced by `to`.
fn edited(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "{from}");
    GOOD.replacen(from, to, 1)
}

/// Parses a bad scene and checks the message names the file, the line (when given) and
/// contains every `needle`.
fn assert_error(text: &str, line: Option<usize>, needles: &[&str]) -> SceneError {
    let e = parse(text).expect_err("the scene should be rejected");
    let msg = e.to_string();
    assert!(msg.starts_with("scenes/bad.toml"), "{msg}");
    if let Some(line) = line {
        assert_eq!(e.position.map(|p| p.0), Some(line), "{msg}");
        assert!(
            msg.starts_with(&format!("scenes/bad.toml:{line}:")),
            "{msg}"
        );
    }
    for n in needles {
        assert!(msg.contains(n), "{msg:?} lacks {n:?}");
    }
    e
}

#[test]
fn the_good_scene_parses() {
    let s = parse(GOOD).unwrap();
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.quads.len(), 1);
    // Integers are accepted where reals are meant, and strength multiplies emission.
    let lamp = s.materials.iter().find(|m| m.name == "lamp").unwrap();
    assert_eq!(lamp.emitted_radiance, glam::Vec3::splat(5.0));
    assert_eq!(s.render.seed, 0);
}

#[test]
fn toml_syntax_error() {
    assert_error(&edited("vfov = 40.0", "vfov = = 40.0"), Some(5), &["TOML"]);
}

#[test]
fn unknown_material_name() {
    assert_error(
        &edited("material = \"white\"", "material = \"whte\""),
        Some(26),
        &[
            "spheres[0].material",
            "unknown material \"whte\"",
            "\"white\"",
        ],
    );
}

#[test]
fn unknown_material_type() {
    assert_error(
        &edited("type = \"diffuse\"", "type = \"glass\""),
        Some(14),
        &["materials.white.type", "unknown material type \"glass\""],
    );
}

#[test]
fn missing_camera() {
    let text = GOOD.replace("[camera]", "[not_camera]");
    let e = parse(&text).unwrap_err();
    // An unknown table is reported first, at its line.
    assert!(e.to_string().contains("not_camera"), "{e}");
    let text = GOOD
        .split_once("[render]")
        .map(|(_, rest)| format!("[render]{rest}"))
        .unwrap();
    assert_error(&text, None, &["[camera]", "missing"]);
}

#[test]
fn zero_or_negative_radius() {
    assert_error(
        &edited("radius = 1.0", "radius = 0.0"),
        Some(25),
        &["spheres[0].radius", "> 0"],
    );
    assert_error(
        &edited("radius = 1.0", "radius = -2"),
        Some(25),
        &["spheres[0].radius"],
    );
}

#[test]
fn degenerate_quad() {
    assert_error(
        &edited("v = [0.0, 0.0, 10.0]", "v = [20.0, 0.0, 0.0]"),
        Some(31),
        &["quads[0].v", "degenerate quad"],
    );
    assert_error(
        &edited("u = [10.0, 0.0, 0.0]", "u = [0.0, 0.0, 0.0]"),
        Some(31),
        &["degenerate"],
    );
}

#[test]
fn zero_width_or_height() {
    assert_error(
        &edited("width = 64", "width = 0"),
        Some(8),
        &["width must be at least 1"],
    );
    assert_error(
        &edited("height = 48", "height = 0"),
        Some(9),
        &["height must be at least 1"],
    );
}

#[test]
fn image_too_large_states_the_limit() {
    assert_error(
        &edited("width = 64", "width = 100000"),
        Some(8),
        &["at most 16384"],
    );
    assert_error(
        &edited("width = 64", "width = 16384").replace("height = 48", "height = 16384"),
        None,
        &["too large to hold", "8388608 pixels"],
    );
}

#[test]
fn nan_or_infinity_anywhere() {
    assert_error(
        &edited("vfov = 40.0", "vfov = nan"),
        Some(5),
        &["camera.vfov", "finite"],
    );
    assert_error(
        &edited("radius = 1.0", "radius = inf"),
        Some(25),
        &["spheres[0].radius", "finite"],
    );
    assert_error(
        &edited("center = [0.0, 1.0, 0.0]", "center = [0.0, -inf, 0.0]"),
        Some(24),
        &["spheres[0].center", "finite"],
    );
    assert_error(
        &edited("color = [0.7, 0.7, 0.7]", "color = [0.7, nan, 0.7]"),
        Some(15),
        &["materials.white.color"],
    );
    assert_error(
        &edited("strength = 5", "strength = inf"),
        Some(21),
        &["materials.lamp.strength"],
    );
    assert_error(
        &edited("eye = [0.0, 1.0, -5.0]", "eye = [1e39, 1.0, -5.0]"),
        Some(2),
        &["camera.eye"],
    );
}

#[test]
fn negative_spp() {
    assert_error(
        &edited("spp = 4", "spp = -4"),
        Some(10),
        &["render.spp", "-4"],
    );
    assert_error(&edited("spp = 4", "spp = 0"), Some(10), &["render.spp"]);
}

#[test]
fn vfov_outside_0_180() {
    for bad in ["0.0", "180.0", "-10", "200"] {
        assert_error(
            &edited("vfov = 40.0", &format!("vfov = {bad}")),
            Some(5),
            &["camera.vfov", "(0, 180)"],
        );
    }
}

/// `projection = "orthographic"` with the view's `height`: read, and each mistake an error
/// naming the field: a field of view, a lens, a height that is missing, not > 0 or not finite,
/// an unknown projection, and a height on a perspective camera.
#[test]
fn orthographic_camera() {
    const ORTHOGRAPHIC: &str = "projection = \"orthographic\"\nheight = 2.5";
    let s = parse(&edited("vfov = 40.0", ORTHOGRAPHIC)).unwrap();
    assert_eq!(
        s.camera.projection,
        glint::scene::Projection::Orthographic { height: 2.5 }
    );
    assert_eq!(s.camera.aperture, 0.0);
    let s = parse(&edited(
        "vfov = 40.0",
        "vfov = 40.0\nprojection = \"perspective\"",
    ))
    .unwrap();
    assert_eq!(
        s.camera.projection,
        glint::scene::Projection::Perspective { vfov: 40.0 }
    );

    let orthographic = |extra: &str| edited("vfov = 40.0", &format!("{ORTHOGRAPHIC}\n{extra}"));
    assert_error(
        &orthographic("vfov = 40.0"),
        Some(7),
        &[
            "camera.vfov",
            "orthographic camera has no field of view",
            "camera.height",
        ],
    );
    for lens in ["aperture = 0.1", "aperture = 0.0", "focus_distance = 3.0"] {
        let field = format!("camera.{}", lens.split(' ').next().unwrap());
        assert_error(
            &orthographic(lens),
            Some(7),
            &[&field, "orthographic camera has no lens", "depth of field"],
        );
    }
    assert_error(
        &edited("vfov = 40.0", "projection = \"orthographic\""),
        None,
        &["camera.height", "missing", "orthographic camera needs"],
    );
    for (bad, needle) in [
        ("0.0", "> 0"),
        ("-2", "> 0"),
        ("nan", "finite"),
        ("inf", "finite"),
    ] {
        assert_error(
            &edited(
                "vfov = 40.0",
                &format!("projection = \"orthographic\"\nheight = {bad}"),
            ),
            Some(6),
            &["camera.height", needle],
        );
    }
    assert_error(
        &edited("vfov = 40.0", "vfov = 40.0\nprojection = \"fisheye\""),
        Some(6),
        &[
            "camera.projection",
            "unknown projection \"fisheye\"",
            "\"orthographic\"",
        ],
    );
    assert_error(
        &edited("vfov = 40.0", "vfov = 40.0\nheight = 2.0"),
        Some(6),
        &["camera.height", "orthographic", "vfov"],
    );
}

#[test]
fn eye_equal_to_target() {
    assert_error(
        &edited("eye = [0.0, 1.0, -5.0]", "eye = [0.0, 1.0, 0.0]"),
        Some(3),
        &["camera.target", "camera.eye"],
    );
}

#[test]
fn up_parallel_to_view_direction() {
    assert_error(
        &edited("up = [0.0, 1.0, 0.0]", "up = [0.0, 0.0, 2.0]"),
        Some(4),
        &["camera.up", "parallel"],
    );
    assert_error(
        &edited("up = [0.0, 1.0, 0.0]", "up = [0.0, 0.0, 0.0]"),
        Some(4),
        &["camera.up"],
    );
}

#[test]
fn empty_file() {
    assert_error("", None, &["empty"]);
    assert_error("  \n# only a comment\n", None, &["[camera]"]);
}

#[test]
fn binary_garbage() {
    assert_error("\u{0}\u{1}\u{2}PNG\u{0}", None, &["NUL", "binary"]);
    assert_error("\x7fELF\x02\x01\x01 garbage ]]]", None, &["TOML"]);
}

#[test]
fn binary_file_that_is_not_utf8() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("garbage.toml");
    std::fs::write(&path, [0x89, b'P', b'N', b'G', 0xff, 0xfe, 0x00, 0x13]).unwrap();
    let e = Scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("garbage.toml") && e.contains("not UTF-8"), "{e}");
}

#[test]
fn missing_file() {
    let e = Scene::load(Path::new("no/such/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("no/such/scene.toml") && e.contains("cannot read"),
        "{e}"
    );
}

#[test]
fn wrong_type_and_unknown_field() {
    assert_error(
        &edited("width = 64", "width = \"wide\""),
        Some(8),
        &["TOML"],
    );
    assert_error(
        &edited("radius = 1.0", "radius = 1.0\nradus = 2.0"),
        Some(26),
        &["radus"],
    );
    assert_error(
        &edited("eye = [0.0, 1.0, -5.0]", "eye = [0.0, 1.0]"),
        Some(2),
        &["camera.eye", "exactly three numbers"],
    );
}

#[test]
fn reflectance_above_one_and_negative_emission() {
    assert_error(
        &edited("color = [0.7, 0.7, 0.7]", "color = [1.5, 0.7, 0.7]"),
        Some(15),
        &["[0, 1]"],
    );
    assert_error(
        &edited("emission = [1.0, 1.0, 1.0]", "emission = [1.0, -1.0, 1.0]"),
        Some(20),
        &["≥ 0"],
    );
}

#[test]
fn new_material_and_camera_fields() {
    let metal = |extra: &str| {
        edited(
            "type = \"diffuse\"\ncolor = [0.7, 0.7, 0.7]",
            &format!("type = \"metal\"\ncolor = [0.7, 0.7, 0.7]\n{extra}"),
        )
    };
    assert!(parse(&metal("roughness = 0.3")).is_ok());
    assert_error(
        &metal("roughness = 1.5"),
        Some(16),
        &["materials.white.roughness", "[0, 1]"],
    );
    assert_error(
        &metal("roughness = -0.1"),
        Some(16),
        &["materials.white.roughness"],
    );
    assert_error(
        &metal(""),
        Some(14),
        &["materials.white.roughness", "missing"],
    );
    let glass = |extra: &str| {
        edited(
            "type = \"diffuse\"\ncolor = [0.7, 0.7, 0.7]",
            &format!("type = \"dielectric\"\n{extra}"),
        )
    };
    let s = parse(&glass("ior = 1.5")).unwrap();
    // A clear glass unless tinted.
    assert_eq!(
        s.materials
            .iter()
            .find(|m| m.name == "white")
            .unwrap()
            .color,
        glam::Vec3::ONE
    );
    assert_error(
        &glass("ior = 0.0"),
        Some(15),
        &["materials.white.ior", "[0.01, 100]"],
    );
    assert_error(&glass("ior = -1.5"), Some(15), &["materials.white.ior"]);
    assert_error(&glass(""), Some(14), &["materials.white.ior", "missing"]);
    assert_error(
        &edited(
            "color = [0.7, 0.7, 0.7]",
            "color = [0.7, 0.7, 0.7]\nior = 1.5",
        ),
        Some(16),
        &["ior does not apply to a diffuse"],
    );
    assert_error(
        &edited("vfov = 40.0", "vfov = 40.0\naperture = -1.0"),
        Some(6),
        &["camera.aperture"],
    );
    assert_error(
        &edited("vfov = 40.0", "vfov = 40.0\nfocus_distance = 0.0"),
        Some(6),
        &["camera.focus_distance", "> 0"],
    );
    let s = parse(&edited("vfov = 40.0", "vfov = 40.0\naperture = 0.2")).unwrap();
    assert_eq!(s.camera.aperture, 0.2);
    // The focus distance defaults to the distance from the eye to the target.
    assert_eq!(s.camera.focus_distance, 5.0);
    assert_error(
        &edited(
            "max_bounces = 4",
            "max_bounces = 4\nlight_sampling = \"yes\"",
        ),
        Some(12),
        &["TOML"],
    );
}

/// `alpha_mode`, `alpha` and `alpha_cutoff`: read where they apply, and each mistake an error
/// naming the field, at its line.
#[test]
fn alpha_fields_are_read_and_checked() {
    use glint::scene::{Alpha, AlphaMode};
    let white = "color = [0.7, 0.7, 0.7]";
    let with = |lines: &str| edited(white, &format!("{white}\n{lines}"));
    let alpha_of = |text: &str| {
        let scene = parse(text).unwrap_or_else(|e| panic!("{e}"));
        scene
            .materials
            .iter()
            .find(|m| m.name == "white")
            .unwrap()
            .alpha
    };
    assert_eq!(alpha_of(GOOD), Alpha::OPAQUE);
    assert_eq!(
        alpha_of(&with(
            "alpha_mode = \"mask\"\nalpha = 0.8\nalpha_cutoff = 0.25"
        )),
        Alpha {
            mode: AlphaMode::Mask { cutoff: 0.25 },
            opacity: 0.8
        }
    );
    assert_eq!(
        alpha_of(&with("alpha_mode = \"mask\"")),
        Alpha {
            mode: AlphaMode::Mask { cutoff: 0.5 },
            opacity: 1.0
        }
    );
    assert_eq!(
        alpha_of(&with("alpha_mode = \"blend\"\nalpha = 0.3")),
        Alpha {
            mode: AlphaMode::Blend,
            opacity: 0.3
        }
    );
    assert_error(
        &with("alpha_mode = \"translucent\""),
        Some(16),
        &[
            "materials.white.alpha_mode",
            "unknown alpha mode \"translucent\"",
            "\"blend\"",
        ],
    );
    assert_error(
        &with("alpha_mode = \"blend\"\nalpha = 1.5"),
        Some(17),
        &["materials.white.alpha", "must be in [0, 1]", "1.5"],
    );
    assert_error(
        &with("alpha = 0.5"),
        Some(16),
        &["materials.white.alpha", "opaque material ignores alpha"],
    );
    assert_error(
        &with("alpha_mode = \"blend\"\nalpha_cutoff = 0.3"),
        Some(17),
        &["materials.white.alpha_cutoff", "only alpha_mode = \"mask\""],
    );
    assert_error(
        &with("alpha_mode = \"mask\"\nalpha_cutoff = -1"),
        Some(17),
        &["materials.white.alpha_cutoff", "must be in [0, 1]", "-1"],
    );
}

/// `[render] sampler` names one of the samplers; `--print-scene` writes it back.
#[test]
fn sampler_is_named() {
    let good = edited("[render]", "[render]\nsampler = \"sobol\"");
    let scene = parse(&good).unwrap();
    assert_eq!(scene.render.sampler, glint::scene::Sampler::Sobol);
    assert_eq!(
        scene.kernel_scene().params.sampler,
        glint::cpu::core::rng::SAMPLER_SOBOL
    );
    let bad = good.replace("\"sobol\"", "\"halton\"");
    assert_error(
        &bad,
        None,
        &["render.sampler", "halton", "independent", "sobol"],
    );
}

/// `GOOD` with a medium `[media.fog]` given by `fields`, filling the sphere.
fn with_medium(fields: &str) -> String {
    edited(
        "material = \"white\"\n",
        "material = \"white\"\nmedium = \"fog\"\n",
    ) + &format!("\n[media.fog]\n{fields}\n")
}

#[test]
fn media_with_bad_coefficients_are_named() {
    for (fields, needles) in [
        (
            "sigma_a = [0.1, -0.2, 0.1]\nsigma_s = [1.0, 1.0, 1.0]",
            &["media.fog.sigma_a", "≥ 0"][..],
        ),
        (
            "sigma_s = [1.0, 1.0]",
            &["media.fog.sigma_s", "three numbers"],
        ),
        (
            "sigma_s = [1.0, 1.0, 1.0]\ng = 1.0",
            &["media.fog.g", "(-1, 1)"],
        ),
        (
            "sigma_s = [1.0, 1.0, 1.0]\ng = -1.5",
            &["media.fog.g", "(-1, 1)"],
        ),
        (
            "color = [0.5, 1.2, 0.5]\ndensity = 1.0",
            &["media.fog.color", "[0, 1]"],
        ),
        ("color = [0.5, 0.5, 0.5]", &["media.fog.density", "missing"]),
        (
            "color = [0.5, 0.5, 0.5]\ndensity = -1.0",
            &["media.fog.density", "got -1"],
        ),
        (
            "color = [0.5, 0.5, 0.5]\nmean_free_path = 0.0",
            &["media.fog.mean_free_path", "must be in"],
        ),
        (
            "sigma_s = [1.0, 1.0, 1.0]\ndensity = 1.0",
            &["media.fog.density", "not both"],
        ),
        ("g = 0.5", &["media.fog.color", "missing"]),
    ] {
        assert_error(&with_medium(fields), None, needles);
    }
}

#[test]
fn unknown_medium_names_are_named_where_they_are_used() {
    let text =
        with_medium("sigma_s = [1.0, 1.0, 1.0]").replace("medium = \"fog\"", "medium = \"smoke\"");
    assert_error(
        &text,
        Some(27),
        &["spheres[0].medium", "unknown medium \"smoke\"", "\"fog\""],
    );
    let text = edited("max_bounces = 4\n", "max_bounces = 4\nmedium = \"haze\"\n");
    assert_error(
        &text,
        Some(12),
        &["render.medium", "unknown medium \"haze\"", "none"],
    );
}

#[test]
fn a_quad_or_an_open_mesh_cannot_hold_a_medium() {
    let text = edited(
        "material = \"lamp\"\n",
        "material = \"lamp\"\nmedium = \"fog\"\n",
    ) + "\n[media.fog]\nsigma_s = [1.0, 1.0, 1.0]\n";
    assert_error(&text, None, &["quads[0].medium", "bounds no volume"]);
    let dir = tempfile::tempdir().unwrap();
    // One triangle: three open edges.
    std::fs::write(
        dir.path().join("open.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let text = format!(
        "{GOOD}\n[[meshes]]\nfile = \"open.obj\"\nmaterial = \"white\"\nmedium = \"fog\"\n\n[media.fog]\nsigma_s = [1.0, 1.0, 1.0]\n"
    );
    let path = dir.path().join("bad.toml");
    let e = Scene::parse(&text, &path).expect_err("an open mesh cannot hold a medium");
    let msg = e.to_string();
    assert!(
        msg.contains("meshes[0].medium") && msg.contains("not closed (3 edges"),
        "{msg}"
    );
}

#[test]
fn an_interface_takes_no_ior_nor_colour() {
    let text = edited(
        "type = \"diffuse\"\ncolor = [0.7, 0.7, 0.7]",
        "type = \"interface\"\nior = 1.5",
    );
    assert_error(
        &text,
        Some(15),
        &["materials.white.ior", "no ior nor color"],
    );
}

/// `GOOD` with the sphere's material a pbr one given `fields` (subsurface scattering).
fn with_subsurface(fields: &str) -> String {
    edited(
        "[materials.white]\ntype = \"diffuse\"\ncolor = [0.7, 0.7, 0.7]\n",
        &format!("[materials.white]\ntype = \"pbr\"\nbase_color = [1.0, 1.0, 1.0]\n{fields}\n"),
    )
}

#[test]
fn subsurface_materials_with_bad_fields_are_named() {
    assert!(parse(&with_subsurface(
        "subsurface_color = [0.8, 0.5, 0.4]\nsubsurface_radius = 0.2"
    ))
    .is_ok());
    for (fields, needles) in [
        (
            "subsurface_color = [0.8, 1.5, 0.4]\nsubsurface_radius = 0.2",
            &["materials.white.subsurface_color", "[0, 1]"][..],
        ),
        (
            "subsurface_color = [0.8, 0.5, 0.4]",
            &["materials.white.subsurface_radius", "missing"],
        ),
        (
            "subsurface_radius = [0.1, 0.2, 0.3]",
            &["materials.white.subsurface_color", "missing"],
        ),
        (
            "subsurface_color = [0.8, 0.5, 0.4]\nsubsurface_radius = -1.0",
            &["materials.white.subsurface_radius", "must be in"],
        ),
        (
            "subsurface_color = [0.8, 0.5, 0.4]\nsubsurface_radius = 0.2\ntransmission = 0.5",
            &["materials.white.transmission", "transmits fully"],
        ),
    ] {
        assert_error(&with_subsurface(fields), None, needles);
    }
    // Not for other types.
    let text = edited(
        "color = [0.7, 0.7, 0.7]\n",
        "color = [0.7, 0.7, 0.7]\nsubsurface_color = [0.8, 0.5, 0.4]\n",
    );
    assert_error(&text, None, &["materials.white.subsurface_color"]);
    // A quad bounds no volume.
    let text = with_subsurface("subsurface_color = [0.8, 0.5, 0.4]\nsubsurface_radius = 0.2")
        .replace("material = \"lamp\"", "material = \"white\"");
    assert_error(&text, None, &["quads[0].material", "bounds no volume"]);
}
