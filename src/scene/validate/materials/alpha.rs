//! A material's `alpha_mode`, `alpha` and `alpha_cutoff`.

use super::super::fields::{fail, FieldError};
use super::unit_interval;
use crate::scene::file::MaterialToml;
use crate::scene::{Alpha, AlphaMode};

/// `alpha_mode` (`"opaque"` unless given), `alpha` (default 1) and `alpha_cutoff` (default
/// 0.5), each checked. The numbers apply only where the mode reads them: `alpha` to mask and
/// blend, `alpha_cutoff` to mask; given elsewhere, they are most likely a mistake.
pub(super) fn alpha(m: &MaterialToml, field: &dyn Fn(&str) -> String) -> Result<Alpha, FieldError> {
    let mode = match &m.alpha_mode {
        None => "opaque",
        Some(mode) => match mode.get_ref().as_str() {
            known @ ("opaque" | "mask" | "blend") => known,
            other => {
                return fail(
                    mode.span(),
                    field("alpha_mode"),
                    format!(
                        "unknown alpha mode {other:?}; known modes: \"opaque\", \"mask\", \"blend\""
                    ),
                )
            }
        },
    };
    if let (Some(a), "opaque") = (&m.alpha, mode) {
        return fail(
            a.span(),
            field("alpha"),
            "an opaque material ignores alpha: add alpha_mode = \"mask\" or \"blend\"",
        );
    }
    if let Some(c) = m.alpha_cutoff.as_ref().filter(|_| mode != "mask") {
        return fail(
            c.span(),
            field("alpha_cutoff"),
            "only alpha_mode = \"mask\" has a cutoff",
        );
    }
    let opacity = m
        .alpha
        .as_ref()
        .map_or(Ok(1.0), |a| unit_interval(a, &field("alpha")))?;
    let mode = match mode {
        "mask" => AlphaMode::Mask {
            cutoff: m
                .alpha_cutoff
                .as_ref()
                .map_or(Ok(0.5), |c| unit_interval(c, &field("alpha_cutoff")))?,
        },
        "blend" => AlphaMode::Blend,
        _ => AlphaMode::Opaque,
    };
    Ok(Alpha { mode, opacity })
}
