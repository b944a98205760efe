//! A stream's decisions as JSON lines and its episodes as a CSV table.

use serde_json::{json, Map, Value};

use crate::causal::{BinDecision, EpisodeSummary};
use crate::pipeline::Encoded;

/// Writes each recording's episode as `neurotex stream --episode whole` prints it for that
/// recording's frames: a line per bin boundary, then its end, each with the recording's
/// `file` (`predict --causal`) and, when its manifest gives one, its `true_label` beside
/// the model's `label` and `decision`.
///
/// # Errors
/// `w` fails.
pub fn write_episodes(
    w: &mut dyn std::io::Write,
    labels: &[String],
    encoded: &[Encoded],
    episodes: &[crate::causal::Episode],
) -> std::io::Result<()> {
    for (e, episode) in encoded.iter().zip(episodes) {
        let file = Some(e.meta.file.as_str());
        let truth = |mut line: Value| {
            if !e.meta.label.is_empty() {
                line["true_label"] = e.meta.label.as_str().into();
            }
            line
        };
        for bin in &episode.bins {
            writeln!(w, "{}", truth(bin_json(labels, bin, file)))?;
        }
        // A whole recording was read or refused as a whole: it had no bad frame.
        let mut end = truth(end_json(labels, &episode.summary, file));
        end["bad_frames"] = 0.into();
        writeln!(w, "{end}")?;
    }
    Ok(())
}

/// A bin boundary's line: `{"t_s", "label", "scores", "decided", "decision"}`, with the
/// recording's `file` first when given (`predict --causal`).
pub fn bin_json(labels: &[String], bin: &BinDecision, file: Option<&str>) -> Value {
    let mut line = Map::new();
    if let Some(file) = file {
        line.insert("file".into(), file.into());
    }
    line.insert("t_s".into(), bin.t_s.into());
    line.insert("label".into(), labels[bin.class].clone().into());
    let scores: Map<String, Value> = labels
        .iter()
        .zip(&bin.shares)
        .map(|(l, &s)| (l.clone(), s.into()))
        .collect();
    line.insert("scores".into(), scores.into());
    line.insert("decided".into(), bin.decided.into());
    line.insert(
        "decision".into(),
        bin.decision.map(|c| labels[c].clone()).into(),
    );
    line.into()
}

/// An episode's end: `{"end": true, "label", "decided_at_s", "decision", "duration_s",
/// "bins", "ended_by"}`; `label` is the whole episode's classification (its last window
/// when longer), null when it is shorter than one bin.
pub fn end_json(labels: &[String], summary: &EpisodeSummary, file: Option<&str>) -> Value {
    let mut line = json!({
        "end": true,
        "label": summary.class.map(|c| labels[c].clone()),
        "decided_at_s": summary.decided_at_s,
        "decision": summary.decision.map(|c| labels[c].clone()),
        "duration_s": summary.duration_s,
        "bins": summary.bins,
        "ended_by": summary.ended_by,
    });
    if let Some(file) = file {
        line["file"] = file.into();
    }
    line
}
