//! `twinpath merge`: the parts of one render (`crate::part_file`) checked to belong together
//! and summed. Nothing is averaged silently: parts from different scene data, settings, seeds
//! or builds, parts that overlap, and gaps between them are errors naming the files.
//!
//! Sums are exact integers (`crate::fixed_sum`), so the merge of a CPU render's parts is the
//! single-process render bit for bit, whatever the split and the order the parts are given.

use crate::film::Film;
use crate::part_file::{read_part, read_part_header, PartHeader};
use crate::sample_range::{Part, SampleRange};
use anyhow::{bail, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Part files read at once (each holds a film's worth of memory while it is added).
const PARALLEL_READS: usize = 4;

/// The merged render.
pub struct Merged {
    pub film: Film,
    /// The samples it holds: the union of the parts' ranges.
    pub samples: SampleRange,
    /// The first part's header (the scene, settings, seed they share).
    pub header: PartHeader,
    /// What the user should know (parts from both backends).
    pub notes: Vec<String>,
}

/// Reads, checks and sums the part files at `paths` (any order).
pub fn merge_parts(paths: &[PathBuf]) -> Result<Merged> {
    let headers = paths
        .iter()
        .map(|p| Ok((p.as_path(), read_part_header(p)?)))
        .collect::<Result<Vec<_>>>()?;
    let (samples, notes) = check_parts(&headers)?;
    // Parts are read (decompressed) a few at a time in parallel and added in order: memory
    // holds the sum and at most PARALLEL_READS parts, whatever their number.
    let parallel = rayon::current_num_threads().clamp(1, PARALLEL_READS);
    let mut film: Option<Film> = None;
    for group in headers.chunks(parallel) {
        let parts = group
            .par_iter()
            .map(|&(path, _)| Ok((path, read_part(path)?)))
            .collect::<Result<Vec<_>>>()?;
        for (path, part) in parts {
            match &mut film {
                None => film = Some(part),
                Some(f) => {
                    if (f.width, f.height) != (part.width, part.height) {
                        bail!(
                            "{}: {}x{} pixels, but {} has {}x{}",
                            path.display(),
                            part.width,
                            part.height,
                            headers[0].0.display(),
                            f.width,
                            f.height
                        );
                    }
                    f.add_film(&part);
                }
            }
        }
    }
    Ok(Merged {
        film: film.expect("at least one part"),
        samples,
        header: headers[0].1.clone(),
        notes,
    })
}

/// Checks that the parts of `headers` (file, header) are of one render and tile one range of
/// samples; returns that range and notes for the user.
pub fn check_parts(headers: &[(&Path, PartHeader)]) -> Result<(SampleRange, Vec<String>)> {
    let Some((first_path, first)) = headers.first() else {
        bail!("no part files to merge");
    };
    let name = |p: &Path| p.display().to_string();
    for (path, h) in &headers[1..] {
        let (a, b) = (name(first_path), name(path));
        if h.version != first.version {
            bail!(
                "{a} was rendered by twinpath {}, {b} by twinpath {}: merge parts of one build",
                first.version,
                h.version
            );
        }
        if h.scene_hash() != first.scene_hash() {
            bail!(
                "{a} and {b} were rendered from different scene data: {}",
                input_difference(first, h, &a, &b)
            );
        }
        if h.seed != first.seed {
            bail!(
                "{a} (seed {}) and {b} (seed {}) have different seeds: their samples are not of one render",
                first.seed,
                h.seed
            );
        }
        if h.settings != first.settings {
            bail!(
                "{a} and {b} were rendered with different settings: {}",
                setting_difference(first, h, &a, &b)
            );
        }
    }
    // Ranges: sorted by start, each must begin where the previous ended.
    let mut order: Vec<usize> = (0..headers.len()).collect();
    order.sort_by_key(|&i| (headers[i].1.samples.start, headers[i].1.samples.end));
    for pair in order.windows(2) {
        let (p, q) = (&headers[pair[0]], &headers[pair[1]]);
        let (r, s) = (p.1.samples, q.1.samples);
        if s.start < r.end {
            bail!(
                "{} (samples {r}) and {} (samples {s}) overlap: a sample would count twice",
                name(p.0),
                name(q.0)
            );
        }
        if s.start > r.end {
            bail!(
                "samples {}..{} are in no part: {} ends at {}, {} starts at {}",
                r.end,
                s.start,
                name(p.0),
                r.end,
                name(q.0),
                s.start
            );
        }
    }
    let union = SampleRange {
        start: headers[order[0]].1.samples.start,
        end: headers[*order.last().expect("one part")].1.samples.end,
    };
    // Parts made by --part I/N name the whole they belong to: it must all be there.
    let mut whole: Option<(&Path, Part, SampleRange)> = None;
    for (path, h) in headers {
        if let Some((part, all)) = h.part {
            match whole {
                None => whole = Some((path, part, all)),
                Some((p, _, w)) if w != all => bail!(
                    "{} is a part of samples {w}, {} of samples {all}: not one render",
                    name(p),
                    name(path)
                ),
                Some(_) => {}
            }
        }
    }
    if let Some((_, part, all)) = whole {
        if union != all {
            let missing: Vec<String> = (0..part.count)
                .map(|index| Part {
                    index,
                    count: part.count,
                })
                .filter(|p| {
                    let r = p.samples(all);
                    r.start < union.start || r.end > union.end
                })
                .map(|p| format!("{p} (samples {})", p.samples(all)))
                .collect();
            bail!(
                "the parts hold samples {union} of {all}: missing part {}",
                missing.join(", ")
            );
        }
    }
    let mut notes = Vec::new();
    if headers.iter().any(|(_, h)| h.backend != first.backend) {
        notes.push(
            "parts from the CPU and the GPU backends: the merge is statistically the same image, \
             not bit-identical to a single render on either backend"
                .to_string(),
        );
    }
    Ok((union, notes))
}

/// Which input file differs between headers `x` (file `a`) and `y` (file `b`).
fn input_difference(x: &PartHeader, y: &PartHeader, a: &str, b: &str) -> String {
    for (i, (path, hash)) in x.inputs.iter().enumerate() {
        match y.inputs.get(i) {
            Some((_, other)) if other != hash => {
                return format!(
                    "{path} has hash {} in {a}, {}'s file {} has {}",
                    short(hash),
                    b,
                    y.inputs[i].0,
                    short(other)
                )
            }
            None => return format!("{a} read {path}, {b} did not"),
            Some(_) => {}
        }
    }
    match y.inputs.get(x.inputs.len()) {
        Some((path, _)) => format!("{b} read {path}, {a} did not"),
        None => "the file lists differ".to_string(),
    }
}

/// The first 16 hex digits of a hash, enough to tell two apart.
fn short(hash: &str) -> &str {
    hash.get(..16).unwrap_or(hash)
}

/// Which setting differs between headers `x` (file `a`) and `y` (file `b`).
fn setting_difference(x: &PartHeader, y: &PartHeader, a: &str, b: &str) -> String {
    for (key, value) in &x.settings {
        match y.settings.iter().find(|(k, _)| k == key) {
            Some((_, other)) if other != value => {
                return format!("{key} is {value} in {a}, {other} in {b}")
            }
            None => return format!("{key} is set in {a}, not in {b}"),
            Some(_) => {}
        }
    }
    "the setting lists differ".to_string()
}
