//! Reading `OUT/alternatives.jsonl` back line by line: the counts of the summary and where
//! each feasible design's record is ([`tally_records`]), then those records by their place
//! ([`read_at`]); memory holds one line and one place per design, not the records.

use super::options::SearchError;
use super::plan::Plan;
use super::record::{AlternativeRecord, Tally};
use std::fs::File;
use std::io::{BufRead, BufReader, Seek, SeekFrom};
use std::path::Path;

/// Read a records file line by line: the summary's counts, and where each feasible
/// design's record is (its alternative number and the byte offset of its line), most
/// robust first (ties: enumeration order).
pub fn tally_records(plan: &Plan, path: &Path) -> Result<(Tally, Vec<(u64, u64)>), SearchError> {
    let io = |source| SearchError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut reader = BufReader::new(File::open(path).map_err(io)?);
    let mut tally = Tally::default();
    let mut designs = Vec::new();
    let mut buf = String::new();
    let mut offset = 0u64;
    let mut line = 0usize;
    loop {
        buf.clear();
        let n = reader.read_line(&mut buf).map_err(io)?;
        if n == 0 {
            break;
        }
        line += 1;
        let bad = |why: String| SearchError::Records {
            path: path.display().to_string(),
            line,
            message: why,
        };
        let rec: AlternativeRecord =
            serde_json::from_str(&buf).map_err(|e| bad(format!("not a record ({e})")))?;
        tally.add(&rec);
        if rec.feasible_design() {
            let place = plan
                .locate(&rec.key)
                .ok_or_else(|| bad(format!("{} is not an alternative of this search", rec.key)))?;
            designs.push((rec.score(), place.index, offset));
        }
        offset += n as u64;
    }
    // Most robust first (ties: enumeration order).
    designs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    Ok((tally, designs.into_iter().map(|(_, i, o)| (i, o)).collect()))
}

/// The records at `places` (alternative number, byte offset) of the records file.
pub(super) fn read_at(
    path: &Path,
    places: &[(u64, u64)],
) -> Result<Vec<AlternativeRecord>, SearchError> {
    let io = |source| SearchError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut reader = BufReader::new(File::open(path).map_err(io)?);
    let mut buf = String::new();
    places
        .iter()
        .map(|&(_, offset)| {
            reader.seek(SeekFrom::Start(offset)).map_err(io)?;
            buf.clear();
            reader.read_line(&mut buf).map_err(io)?;
            serde_json::from_str(&buf).map_err(|e| SearchError::Records {
                path: path.display().to_string(),
                line: 0,
                message: format!("the record at byte {offset} is not readable any more ({e})"),
            })
        })
        .collect()
}
