//! `[media.NAME]`: homogeneous media, their coefficients checked, and references to them by
//! name (`medium = "NAME"` on `[render]`, `[camera]`, spheres and meshes).

use super::super::file::{MaterialToml, MediumToml, Real, Triple, S};
use super::super::grid::read_density_grid;
use super::super::limits::{MAX_COORDINATE, MIN_LENGTH};
use super::super::medium::{GridMedium, Medium, MAX_COEFFICIENT};
use super::super::MaterialKind;
use super::fields::{fail, real, vec3, FieldError};
use super::materials::Materials;
use glam::{Mat4, Vec3};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

/// The scene's media, and their indices by name.
pub(super) struct MediaNames {
    pub(super) list: Vec<Medium>,
    index_of: BTreeMap<String, u32>,
}

impl MediaNames {
    /// The index of the medium `m` names; an unknown name fails at `field`.
    pub(super) fn reference(&self, m: &S<String>, field: &str) -> Result<u32, FieldError> {
        self.index_of.get(m.get_ref()).copied().ok_or_else(|| {
            let known: Vec<_> = self.index_of.keys().map(|k| format!("{k:?}")).collect();
            FieldError {
                span: Some(m.span()),
                field: field.into(),
                message: format!(
                    "unknown medium {:?}; defined media: {}",
                    m.get_ref(),
                    if known.is_empty() {
                        "none (define one with [media.NAME])".into()
                    } else {
                        known.join(", ")
                    }
                ),
            }
        })
    }
}

impl MediaNames {
    /// The index of the homogeneous medium `m` names, for an object, the scene or the camera
    /// to be filled with: a grid medium is placed by `[[volumes]]` only.
    pub(super) fn homogeneous(&self, m: &S<String>, field: &str) -> Result<u32, FieldError> {
        let index = self.reference(m, field)?;
        if self.list[index as usize].grid.is_some() {
            return fail(
                m.span(),
                field,
                format!(
                    "medium {:?} has a density grid, which a [[volumes]] entry places (its \
                     grid fills a box around its active voxels); only homogeneous media fill \
                     objects, the scene or the camera's surroundings",
                    m.get_ref()
                ),
            );
        }
        Ok(index)
    }
}

/// The `[media]` tables, in name order; grid files are read relative to `folder`.
pub(super) fn validate_media(
    toml: &BTreeMap<String, S<MediumToml>>,
    folder: &Path,
) -> Result<MediaNames, FieldError> {
    let mut list = Vec::new();
    let mut index_of = BTreeMap::new();
    for (name, m) in toml {
        index_of.insert(name.clone(), list.len() as u32);
        let mut medium = validate_medium(name, m)?;
        medium.grid = medium_grid(name, m.get_ref(), folder)?;
        list.push(medium);
    }
    Ok(MediaNames { list, index_of })
}

/// `grid` and `grid_name`: the density grid, read, or `None` for a homogeneous medium.
fn medium_grid(
    name: &str,
    m: &MediumToml,
    folder: &Path,
) -> Result<Option<GridMedium>, FieldError> {
    let Some(file) = &m.grid else {
        if let Some(g) = &m.grid_name {
            return fail(
                g.span(),
                format!("media.{name}.grid_name"),
                "grid_name names a grid of the file that grid gives: give grid as well",
            );
        }
        return Ok(None);
    };
    let grid_name = m.grid_name.as_ref().map_or("density", |g| g.get_ref());
    let path = folder.join(file.get_ref());
    let grid = read_density_grid(&path, grid_name).map_err(|message| FieldError {
        span: Some(file.span()),
        field: format!("media.{name}.grid"),
        message,
    })?;
    Ok(Some(GridMedium {
        grid: Arc::new(grid),
        placement: Mat4::IDENTITY,
    }))
}

/// `[media.NAME]`: exactly one of the two forms, every coefficient ≥ 0 and finite, |g| < 1.
fn validate_medium(name: &str, m: &S<MediumToml>) -> Result<Medium, FieldError> {
    let field = |f: &str| format!("media.{name}.{f}");
    let span = m.span();
    let m = m.get_ref();
    let physical = m.sigma_a.is_some() || m.sigma_s.is_some();
    let artist = m.color.is_some() || m.density.is_some() || m.mean_free_path.is_some();
    let (sigma_a, sigma_s) = if physical {
        if artist {
            let which = if m.color.is_some() {
                "color"
            } else if m.density.is_some() {
                "density"
            } else {
                "mean_free_path"
            };
            return fail(
                span,
                field(which),
                "give either sigma_a and sigma_s, or color with density or mean_free_path, not both",
            );
        }
        let a = m
            .sigma_a
            .as_ref()
            .map_or(Ok(Vec3::ZERO), |s| coefficient(s, &field("sigma_a")))?;
        let s = m
            .sigma_s
            .as_ref()
            .map_or(Ok(Vec3::ZERO), |s| coefficient(s, &field("sigma_s")))?;
        (a, s)
    } else {
        let Some(color) = &m.color else {
            return fail(
                span,
                field("color"),
                "missing: a medium needs sigma_a and sigma_s, or color with density or mean_free_path",
            );
        };
        let albedo = vec3(color, &field("color"))?;
        if albedo.min_element() < 0.0 || albedo.max_element() > 1.0 {
            return fail(
                color.span(),
                field("color"),
                format!("the single-scattering albedo must be in [0, 1] per channel, got {albedo}"),
            );
        }
        let sigma_t = match (&m.density, &m.mean_free_path) {
            (Some(d), None) => {
                let d = real(d, &field("density")).and_then(|v| {
                    if !(0.0..=MAX_COEFFICIENT).contains(&v) {
                        fail(
                            d.span(),
                            field("density"),
                            format!("must be in [0, {MAX_COEFFICIENT:e}] per unit length, got {v}"),
                        )
                    } else {
                        Ok(v)
                    }
                })?;
                Vec3::splat(d)
            }
            (None, Some(p)) => mean_free_path(p, &field("mean_free_path"))?.recip(),
            (Some(_), Some(p)) => {
                return fail(
                    p.span(),
                    field("mean_free_path"),
                    "give density or mean_free_path, not both",
                )
            }
            (None, None) => {
                return fail(
                    color.span(),
                    field("density"),
                    "missing: a medium given by color needs density or mean_free_path",
                )
            }
        };
        (sigma_t * (Vec3::ONE - albedo), sigma_t * albedo)
    };
    let g = match &m.g {
        Some(g) => {
            let v = real(g, &field("g"))?;
            // At ±1 the phase function is a delta, which neither sampling nor its pdf handles.
            if v.abs() >= 1.0 {
                return fail(
                    g.span(),
                    field("g"),
                    format!("must be in (-1, 1) (0 scatters evenly, > 0 forwards), got {v}"),
                );
            }
            v
        }
        None => 0.0,
    };
    Ok(Medium {
        name: name.into(),
        sigma_a,
        sigma_s,
        g,
        grid: None,
    })
}

/// An absorption or scattering coefficient per channel: finite, in [0, MAX_COEFFICIENT].
fn coefficient(x: &S<Triple>, field: &str) -> Result<Vec3, FieldError> {
    let v = vec3(x, field)?;
    if v.min_element() < 0.0 {
        return fail(
            x.span(),
            field,
            format!("coefficients must be ≥ 0 (per unit length), got {v}"),
        );
    }
    if v.max_element() > MAX_COEFFICIENT {
        return fail(
            x.span(),
            field,
            format!("coefficients must be at most {MAX_COEFFICIENT:e} per unit length, got {v}"),
        );
    }
    Ok(v)
}

/// A mean free path: one length or three, each in [MIN_LENGTH, MAX_COORDINATE].
fn mean_free_path(x: &S<toml::Value>, field: &str) -> Result<Vec3, FieldError> {
    let v = match x.get_ref() {
        toml::Value::Float(f) => Vec3::splat(real(&S::new(x.span(), Real(*f)), field)?),
        toml::Value::Integer(i) => Vec3::splat(*i as f32),
        _ => vec3(x, field)?,
    };
    if v.min_element() < MIN_LENGTH || v.max_element() > MAX_COORDINATE {
        return fail(
            x.span(),
            field,
            format!(
                "must be in [{MIN_LENGTH:e}, {MAX_COORDINATE:e}] (a length glint supports), got {v}"
            ),
        );
    }
    Ok(v)
}

/// The media `subsurface_color` and `subsurface_radius` make (random-walk subsurface
/// scattering, as Cycles' `random_walk`): for each pbr material that has them, a medium added
/// to `media` and the material made fully transmissive (a dielectric boundary over the
/// medium). Returns, per such material's index, its medium's index.
///
/// The colour is the albedo after many scatterings, as artists pick it; the medium's
/// single-scattering albedo α and extinction σt come from it and the radius d by Chiang, Kutz
/// and Burley's fit ("Practical and Controllable Subsurface Scattering for Production Path
/// Tracing", 2016, which Cycles uses): α = 1 − exp(A (−5.09406 + A (2.61188 − 4.31805 A))),
/// σt = 1 / (d (1.9 − A + 3.5 (A − 0.8)²)), per channel; isotropic (g = 0).
pub(super) fn subsurface_media(
    toml: &BTreeMap<String, S<MaterialToml>>,
    materials: &mut Materials,
    media: &mut MediaNames,
) -> Result<BTreeMap<u32, u32>, FieldError> {
    let mut filled = BTreeMap::new();
    for (name, m) in toml {
        let m = m.get_ref();
        if m.subsurface_color.is_none() && m.subsurface_radius.is_none() {
            continue;
        }
        let field = |f: &str| format!("materials.{name}.{f}");
        let (Some(color), Some(radius)) = (&m.subsurface_color, &m.subsurface_radius) else {
            let (given, missing, span) = match (&m.subsurface_color, &m.subsurface_radius) {
                (Some(c), _) => ("subsurface_color", "subsurface_radius", c.span()),
                (_, Some(r)) => ("subsurface_radius", "subsurface_color", r.span()),
                _ => unreachable!("one of them is given"),
            };
            return Err(FieldError {
                span: Some(span),
                field: field(missing),
                message: format!("missing: {given} needs {missing} as well"),
            });
        };
        let albedo = vec3(color, &field("subsurface_color"))?;
        if albedo.min_element() < 0.0 || albedo.max_element() > 1.0 {
            return fail(
                color.span(),
                field("subsurface_color"),
                format!("must be in [0, 1] per channel, got {albedo}"),
            );
        }
        let radius = mean_free_path(radius, &field("subsurface_radius"))?;
        if let Some(t) = &m.transmission {
            if t.get_ref().0 != 1.0 {
                return fail(
                    t.span(),
                    field("transmission"),
                    "a subsurface material transmits fully (its surface is a dielectric over \
                     the medium): leave transmission out, or set it to 1",
                );
            }
        }
        let fit = |a: f32, d: f32| {
            let single = 1.0 - (a * (-5.09406 + a * (2.61188 - a * 4.31805))).exp();
            let extinction = 1.0 / (d * (1.9 - a + 3.5 * (a - 0.8) * (a - 0.8)));
            (single, extinction.min(MAX_COEFFICIENT))
        };
        let mut sigma_a = Vec3::ZERO;
        let mut sigma_s = Vec3::ZERO;
        for c in 0..3 {
            let (single, extinction) = fit(albedo[c], radius[c]);
            sigma_s[c] = single * extinction;
            sigma_a[c] = (1.0 - single) * extinction;
        }
        let material = materials
            .index(name)
            .expect("every [materials] table was validated");
        if let MaterialKind::Pbr { transmission, .. } = &mut materials.list[material as usize].kind
        {
            *transmission = 1.0;
        }
        media.list.push(Medium {
            name: format!("{name} (subsurface)"),
            sigma_a,
            sigma_s,
            g: 0.0,
            grid: None,
        });
        filled.insert(material, media.list.len() as u32 - 1);
    }
    Ok(filled)
}

/// The medium the camera starts in, once volumes are placed: `declared` (`[camera] medium`),
/// or the grid medium of the one volume whose box holds the eye. A camera inside a volume
/// needs no declaration, as no file could name the volume's medium (each volume's is a copy
/// of its own); one inside a volume and a declared medium, or inside two volumes, is refused:
/// a camera starts in one medium above the global one.
pub(super) fn camera_in_volume(
    media: &MediaNames,
    boundaries: &[(u32, u32)],
    eye: glam::Vec3,
    declared: Option<u32>,
) -> Result<Option<u32>, String> {
    let holding: Vec<u32> = boundaries
        .iter()
        .map(|&(_, medium)| medium)
        .filter(|&m| {
            media.list[m as usize]
                .grid
                .as_ref()
                .is_some_and(|g| g.grid.box_contains(&g.placement, eye))
        })
        .collect();
    let name = |m: u32| media.list[m as usize].name.clone();
    match (holding.as_slice(), declared) {
        ([], _) => Ok(declared),
        ([volume], None) => Ok(Some(*volume)),
        ([volume], Some(declared)) => Err(format!(
            "the camera is inside the box of {} and also in medium {:?} ([camera] medium); \
                 glint starts a camera in one medium: move the eye out of the volume's box",
            name(*volume),
            name(declared)
        )),
        (several, _) => Err(format!(
            "the camera is inside the boxes of {}; glint starts a camera in one medium: \
                 move the eye out of all but one",
            several
                .iter()
                .map(|&m| name(m))
                .collect::<Vec<_>>()
                .join(" and ")
        )),
    }
}

/// One warning per grid that was averaged down to fit one GPU binding, naming its file and
/// grid, the sizes and the factor (volumes' copies of a medium share its grid: said once).
pub(super) fn downsampling_warnings(media: &MediaNames) -> Vec<String> {
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for grid in media.list.iter().filter_map(|m| m.grid.as_ref()) {
        let g = &grid.grid;
        if g.downsampled > 1 && seen.insert(g.source.clone()) {
            let [x, y, z] = g.read_dims;
            let [cx, cy, cz] = g.dims;
            out.push(format!(
                "{}: the grid spans {x} × {y} × {z} voxels, more than one GPU binding holds; \
                 glint averaged it over {f}³ blocks to {cx} × {cy} × {cz} voxels (detail finer \
                 than {f} voxels is lost; resample the grid coarser to choose how)",
                g.source,
                f = g.downsampled
            ));
        }
    }
    out
}
