//! Merging partial renders (`glint merge`): checks that the parts are of one render (same
//! scene and settings, seed, size and total spp), that no sample is in two of them and that
//! none is missing, then combines them with the exact pairwise update
//! ([`Accumulation::merge`]) in the order of their samples, as a single render would have.

use crate::render::accumulation::Accumulation;
use crate::render::partial::{format_range, Partial, PartialInfo};
use std::ops::Range;
use std::path::PathBuf;

/// A partial and the file it came from.
pub struct Part {
    pub path: PathBuf,
    pub partial: Partial,
}

/// The merged render and what went into it.
pub struct Merged {
    pub partial: Partial,
    /// Parts of 0..spp that no input held (only with `allow_gaps`).
    pub missing: Vec<Range<u32>>,
}

/// Merges `parts` (at least one). Every refusal is a message naming the files concerned.
pub fn merge(mut parts: Vec<Part>, allow_gaps: bool) -> Result<Merged, String> {
    let first = parts.first().ok_or("nothing to merge")?;
    let (reference, reference_path) = (&first.partial, first.path.display().to_string());
    let info = reference.info.clone();
    let info = &info;
    let size = |p: &Partial| (p.accumulation.width, p.accumulation.height);
    for part in &parts[1..] {
        let other = &part.partial;
        let name = part.path.display();
        if other.info.seed != info.seed {
            return Err(format!(
                "{reference_path} has seed {} but {name} has seed {}: they are samples of different renders",
                info.seed, other.info.seed
            ));
        }
        if size(other) != size(reference) {
            let ((w1, h1), (w2, h2)) = (size(reference), size(other));
            return Err(format!(
                "{reference_path} is {w1}×{h1} but {name} is {w2}×{h2}"
            ));
        }
        if other.info.settings != info.settings {
            return Err(format!(
                "{reference_path} and {name} are renders of different scenes or settings (settings hash {}… vs {}…)",
                &info.settings[..info.settings.len().min(12)],
                &other.info.settings[..other.info.settings.len().min(12)]
            ));
        }
        if other.info.spp != info.spp {
            return Err(format!(
                "{reference_path} is part of a {} spp render but {name} of a {} spp one",
                info.spp, other.info.spp
            ));
        }
    }

    // Every range with its file, in sample order.
    let mut ranges: Vec<(Range<u32>, &str)> = Vec::new();
    let names: Vec<String> = parts.iter().map(|p| p.path.display().to_string()).collect();
    for (part, name) in parts.iter().zip(&names) {
        for r in &part.partial.info.ranges {
            ranges.push((r.clone(), name));
        }
    }
    ranges.sort_by_key(|(r, _)| (r.start, r.end));
    for w in ranges.windows(2) {
        let ((a, name_a), (b, name_b)) = (&w[0], &w[1]);
        if b.start < a.end {
            let what = if name_a == name_b {
                format!(
                    "{name_a} overlaps itself in samples {} (a file given twice?)",
                    format_range(&(b.start..a.end.min(b.end)))
                )
            } else {
                format!(
                    "{name_a} ({}) and {name_b} ({}) overlap in samples {}",
                    format_range(a),
                    format_range(b),
                    format_range(&(b.start..a.end.min(b.end)))
                )
            };
            return Err(what);
        }
    }
    let mut missing = Vec::new();
    let mut covered = 0;
    let mut describe_gaps = Vec::new();
    for (i, (r, name)) in ranges.iter().enumerate() {
        if r.start > covered {
            missing.push(covered..r.start);
            let before = if i == 0 {
                "before".to_string()
            } else {
                format!("between {} and", ranges[i - 1].1)
            };
            describe_gaps.push(format!(
                "{} ({before} {name})",
                format_range(&(covered..r.start))
            ));
        }
        covered = r.end;
    }
    if covered < info.spp {
        missing.push(covered..info.spp);
        describe_gaps.push(format!(
            "{} (after {})",
            format_range(&(covered..info.spp)),
            ranges.last().expect("at least one range").1
        ));
    }
    if !missing.is_empty() && !allow_gaps {
        return Err(format!(
            "samples missing from the {} spp render: {}; render them, or pass --allow-gaps to merge what is there",
            info.spp,
            describe_gaps.join(", ")
        ));
    }

    // Fold in sample order. Starting from an empty accumulation copies the first part exactly,
    // as the kernel's first batch does.
    let (width, height) = size(reference);
    let ranges: Vec<Range<u32>> = ranges.into_iter().map(|(r, _)| r).collect();
    parts.sort_by_key(|p| p.partial.info.ranges[0].start);
    let mut total = Accumulation::empty(width, height);
    let mut devices: Vec<String> = Vec::new();
    for part in &parts {
        total.merge(&part.partial.accumulation);
        if !devices.contains(&part.partial.info.device) {
            devices.push(part.partial.info.device.clone());
        }
    }
    let info = PartialInfo {
        ranges: coalesce(ranges.into_iter()),
        target: 0..info.spp,
        spp: info.spp,
        seed: info.seed,
        settings: info.settings.clone(),
        scene: info.scene.clone(),
        device: devices.join(", "),
        // The settings where every part has the same, none otherwise.
        adaptive: parts
            .iter()
            .map(|p| p.partial.info.adaptive)
            .reduce(|a, b| if a == b { a } else { None })
            .flatten(),
    };
    Ok(Merged {
        partial: Partial {
            info,
            accumulation: total,
        },
        missing,
    })
}

/// Sorted, disjoint ranges with touching neighbours joined.
fn coalesce(sorted: impl Iterator<Item = Range<u32>>) -> Vec<Range<u32>> {
    let mut out: Vec<Range<u32>> = Vec::new();
    for r in sorted {
        match out.last_mut() {
            Some(last) if last.end == r.start => last.end = r.end,
            _ => out.push(r),
        }
    }
    out
}
