//! Which sample indices a render takes: all of `0..spp`, one part `I/N` of them, or an explicit
//! range `A..B`. Samples are a pure function of (scene, settings, seed, pixel, sample index),
//! so the parts of a render can run anywhere and be merged (docs/parts.md).

use anyhow::{bail, Result};
use std::fmt;

/// Sample indices `start..end` of every pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SampleRange {
    pub start: u32,
    pub end: u32,
}

impl SampleRange {
    /// All `spp` samples: `0..spp`.
    pub fn all(spp: u32) -> Self {
        Self { start: 0, end: spp }
    }

    /// Samples per pixel in the range.
    pub fn len(&self) -> u32 {
        self.end - self.start
    }

    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }

    /// Reads `A..B` (`A < B`).
    pub fn parse(text: &str) -> Result<Self> {
        let (start, end) = two_numbers(
            text,
            "..",
            "a range A..B of sample indices",
            "a sample index",
        )?;
        if start >= end {
            bail!("'{text}' is empty: A..B needs A < B");
        }
        Ok(Self { start, end })
    }
}

impl fmt::Display for SampleRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.start, self.end)
    }
}

/// Part `index` of `count` parts (`index` counts from 0, as the array indices of Slurm,
/// Kubernetes Indexed Jobs and AWS Batch do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Part {
    pub index: u32,
    pub count: u32,
}

impl Part {
    /// Reads `I/N` (`0 <= I < N`).
    pub fn parse(text: &str) -> Result<Self> {
        let (index, count) = two_numbers(
            text,
            "/",
            "I/N (part I of N, I counting from 0)",
            "a number",
        )?;
        if count == 0 {
            bail!("'{text}': a render has at least one part");
        }
        if index >= count {
            bail!(
                "'{text}': parts count from 0, so part I of {count} has I in 0..={}",
                count - 1
            );
        }
        Ok(Self { index, count })
    }

    /// The part's share of `all`: split as evenly as whole samples allow, part `i` taking
    /// `start + floor(i * n / N) .. start + floor((i + 1) * n / N)`. The parts of one `all`
    /// tile it with neither gaps nor overlaps.
    pub fn samples(&self, all: SampleRange) -> SampleRange {
        let n = all.len() as u64;
        let at = |i: u32| all.start + (i as u64 * n / self.count as u64) as u32;
        SampleRange {
            start: at(self.index),
            end: at(self.index + 1),
        }
    }
}

/// The two numbers of `text`, written `X<separator>Y`; errors say that `text` is not `form`,
/// or which number is not `number`.
fn two_numbers(text: &str, separator: &str, form: &str, number: &str) -> Result<(u32, u32)> {
    let Some((a, b)) = text.split_once(separator) else {
        bail!("'{text}' is not {form}");
    };
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| anyhow::anyhow!("'{s}' in '{text}' is not {number}"))
    };
    Ok((parse(a)?, parse(b)?))
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_tile_the_samples() {
        for spp in [1u32, 7, 64, 1000, u32::MAX] {
            for count in [1u32, 2, 3, 7, 16] {
                if count > spp {
                    continue;
                }
                let all = SampleRange::all(spp);
                let mut next = 0;
                for index in 0..count {
                    let r = Part { index, count }.samples(all);
                    assert_eq!(r.start, next, "{spp} spp, part {index}/{count}");
                    assert!(r.len() >= spp / count && r.len() <= spp.div_ceil(count));
                    next = r.end;
                }
                assert_eq!(next, spp);
            }
        }
    }

    #[test]
    fn bad_parts_and_ranges_are_errors() {
        assert!(Part::parse("4/4").is_err());
        assert!(Part::parse("0/0").is_err());
        assert!(Part::parse("1-4").is_err());
        assert_eq!(Part::parse("3/4").unwrap(), Part { index: 3, count: 4 });
        assert!(SampleRange::parse("5..5").is_err());
        assert!(SampleRange::parse("5..").is_err());
        assert_eq!(
            SampleRange::parse("16..32").unwrap(),
            SampleRange { start: 16, end: 32 }
        );
    }
}
