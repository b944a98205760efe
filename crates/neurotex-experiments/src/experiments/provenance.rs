//! Where a set of results comes from: the code, the parameters, the data and the date.

use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use super::{Source, ValidReproduceParams};
use crate::error::Result;

/// Enough to tell two sets of results apart, and to run one again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// neurotex's version.
    pub neurotex_version: String,
    /// The git commit neurotex was built from, when built from a checkout.
    pub git_commit: Option<String>,
    /// Every parameter, as the report lists them.
    pub parameters: Vec<String>,
    /// The data: a dataset folder's fingerprint (SHA-256 of its manifest and file sizes), or
    /// the simulated design and its seed.
    pub data: String,
    /// When the run started, UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub created_utc: String,
}

impl Provenance {
    /// The provenance of a run on `source` with `params`, now.
    ///
    /// # Errors
    /// A dataset's manifest or a listed file can no longer be read.
    pub fn of(source: &Source, params: &ValidReproduceParams) -> Result<Self> {
        let (data, layout, slides) = match source {
            Source::Dataset(ds) => (
                format!("{} ({})", ds.fingerprint()?, ds.root.display()),
                ds.layout.baseline,
                slide_times(&ds.entries),
            ),
            Source::Simulated { trials, seed, .. } => {
                let data = format!("simulated: {} trials, seed {seed}", trials.len());
                (data, None, [trials.len(); 2])
            }
        };
        let commit = env!("NEUROTEX_GIT_COMMIT");
        Ok(Provenance {
            neurotex_version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: (!commit.is_empty()).then(|| commit.to_string()),
            parameters: params.describe(layout, slides),
            data,
            created_utc: utc_timestamp(SystemTime::now()),
        })
    }
}

/// How many of `entries` have their slide's times in the manifest, and how many there are.
pub fn slide_times(entries: &[crate::recording::Meta]) -> [usize; 2] {
    let with = entries
        .iter()
        .filter(|e| e.slide_start_s.is_some() && e.slide_end_s.is_some());
    [with.count(), entries.len()]
}

/// `neurotex VERSION`, and `, commit HASH` when built from a git checkout.
pub fn build() -> String {
    let commit = env!("NEUROTEX_GIT_COMMIT");
    match commit.is_empty() {
        true => format!("neurotex {}", env!("CARGO_PKG_VERSION")),
        false => format!("neurotex {}, commit {commit}", env!("CARGO_PKG_VERSION")),
    }
}

/// Now, UTC, `YYYY-MM-DDTHH:MM:SSZ`.
pub fn now_utc() -> String {
    utc_timestamp(SystemTime::now())
}

/// `YYYY-MM-DDTHH:MM:SSZ` of `time`. Written here (days to a civil date, the algorithm of
/// Howard Hinnant's `civil_from_days`) because one timestamp does not justify a date crate.
fn utc_timestamp(time: SystemTime) -> String {
    let secs = time.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs()) as i64;
    let (days, rest) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    let (h, m, s) = (rest / 3600, rest % 3600 / 60, rest % 60);
    format!("{year:04}-{month:02}-{day:02}T{h:02}:{m:02}:{s:02}Z")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn timestamps_by_hand() {
        let at = |s: u64| utc_timestamp(UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        // 2000-02-29 12:34:56 UTC, a leap day (date -u -d @951827696)
        assert_eq!(at(951_827_696), "2000-02-29T12:34:56Z");
        // 2026-11-22 00:00:00 UTC (date -u -d @1795305600)
        assert_eq!(at(1_795_305_600), "2026-11-22T00:00:00Z");
    }
}
