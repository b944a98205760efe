//! The CSV of `reproduce`'s headline predictions, which the binary writes beside the report.

use crate::experiments::HeadlinePrediction;

/// Writes the headline predictions as CSV, `speed_mm_s,method,file,label,predicted,fold,
/// repeat`, one row per prediction (`fold` is `test` for a train/test split).
///
/// # Errors
/// Writing fails.
pub fn write_headline_predictions(
    w: &mut dyn std::io::Write,
    predictions: &[HeadlinePrediction],
) -> std::io::Result<()> {
    let mut out = csv::Writer::from_writer(w);
    let header = [
        "speed_mm_s",
        "method",
        "file",
        "label",
        "predicted",
        "fold",
        "repeat",
    ];
    out.write_record(header)?;
    for p in predictions {
        let fold = p.fold.map_or("test".to_string(), |f| f.to_string());
        out.write_record([
            p.speed.to_string().as_str(),
            p.method,
            &p.file,
            &p.label,
            &p.predicted,
            &fold,
            &p.repeat.to_string(),
        ])?;
    }
    out.flush()
}
