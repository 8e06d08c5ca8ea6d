//! One CSV row per finished part (`[output] parts_csv = true`): arrival and end times, class,
//! cause, contacts, entry and final orientation and lateral position.

use crate::engine::PartRecord;
use crate::report::ReportResult;
use std::path::Path;

/// Write the records, sorted by part index.
pub fn write_parts_csv(path: &Path, records: &[PartRecord]) -> ReportResult<()> {
    let mut sorted: Vec<&PartRecord> = records.iter().collect();
    sorted.sort_by_key(|r| r.part);
    crate::output::produce_atomic(path, |tmp| {
        let mut w = csv::Writer::from_path(tmp)?;
        for r in sorted {
            w.serialize(r)?;
        }
        w.flush()?;
        Ok(())
    })
}
