//! `alternatives.parquet`: the records of `alternatives.jsonl` as one columnar file that
//! pandas, Polars and DuckDB read directly (issue 35). It is written at the end of a run
//! (and by `merge`) from the JSONL, which stays the file a killed run streams into, so the
//! two always hold the same records in the same order.
//!
//! The schema is [`columns`]: every scalar of a record a typed column, the nested parts
//! whose shape is fixed (`verification`, each margin of `robustness`) flattened into
//! columns, the parts whose shape varies from graph to graph or task to task
//! (`variables`, `requirements`, `cycle`, the first intersection found, …) one JSON text
//! column each; `modes` is one text `up,down,…`. A field no column holds (a record field
//! newer than this schema, or a value of another type than its column's) goes whole into
//! the JSON object of `other`, so [`read_records`] gives back every record exactly. Two
//! more columns are derived from the record: `id` (the design's file name) and `design`
//! (a feasible design, as the summary counts them). The file's key-value metadata
//! `foldsynth:columns` repeats the schema: each column's name, path in the record, kind
//! (`text`, `int`, `float`, `bool`, `json`, `joined`), unit and meaning.

use super::options::SearchError;
use super::output::{OutputDir, RECORDS};
use super::record::AlternativeRecord;
use ::parquet::basic::Compression;
use ::parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int64Type};
use ::parquet::file::metadata::KeyValue;
use ::parquet::file::properties::WriterProperties;
use ::parquet::file::reader::{FileReader, SerializedFileReader};
use ::parquet::file::writer::SerializedFileWriter;
use ::parquet::record::Field;
use ::parquet::schema::parser::parse_message_type;
use serde_json::{Map, Value};
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::sync::Arc;

/// The results file.
pub const PARQUET: &str = "alternatives.parquet";

/// Records per row group (a row group is held in memory while it is written).
const ROW_GROUP: usize = 16_384;

/// A column's type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// UTF-8 text.
    Text,
    /// 64-bit integer.
    Int,
    /// 64-bit float.
    Float,
    /// Boolean.
    Bool,
    /// A JSON document as UTF-8 text.
    Json,
    /// A list of texts joined by `,` (`modes`).
    Joined,
}

/// One column: its name, where it is in a record (a field, or a field of a field), its
/// type, unit and meaning.
#[derive(Clone, Copy, Debug)]
pub struct Column {
    /// Column name.
    pub name: &'static str,
    /// Path in the record's JSON object; empty for a derived column.
    pub path: &'static [&'static str],
    /// Type.
    pub kind: Kind,
    /// Unit ("" for none).
    pub unit: &'static str,
    /// What it holds.
    pub doc: &'static str,
}

const fn col(
    name: &'static str,
    path: &'static [&'static str],
    kind: Kind,
    unit: &'static str,
    doc: &'static str,
) -> Column {
    Column {
        name,
        path,
        kind,
        unit,
        doc,
    }
}

/// A margin of `robustness` flattened: value, setting, state and place.
macro_rules! margin {
    ($m:literal, $unit:literal) => {
        [
            col(
                $m,
                &["robustness", $m, "value"],
                Kind::Float,
                $unit,
                concat!("smallest ", $m, " over the sweep"),
            ),
            col(
                concat!($m, "_setting"),
                &["robustness", $m, "setting"],
                Kind::Float,
                $unit,
                concat!("the task's setting for ", $m),
            ),
            col(
                concat!($m, "_t"),
                &["robustness", $m, "t"],
                Kind::Float,
                "t (motion parameter)",
                concat!("the state where ", $m, " is smallest"),
            ),
            col(
                concat!($m, "_where"),
                &["robustness", $m, "where"],
                Kind::Text,
                "",
                concat!("the vertex, facet pair or obstacle of ", $m),
            ),
        ]
    };
}

const MARGINS: [[Column; 4]; 5] = [
    margin!("rigid_margin", "rad"),
    margin!("self_clearance", "paper units"),
    margin!("arm_clearance", "paper units"),
    margin!("obstacle_clearance", "paper units"),
    margin!("min_feature", "paper units"),
];

use Kind::{Bool, Float, Int, Joined, Json, Text};

/// The columns before the margins.
const HEAD: &[Column] = &[
    col(
        "id",
        &[],
        Text,
        "",
        "derived: the design's id g<graph>-c<candidate>-<modes> (designs/<id>.json)",
    ),
    col(
        "design",
        &[],
        Bool,
        "",
        "derived: a feasible design (passes every check, keeps the margins)",
    ),
    col(
        "key",
        &["key"],
        Text,
        "",
        "sequence|candidate|modes, unique in a run",
    ),
    col(
        "graph",
        &["graph"],
        Int,
        "",
        "index among the meaningful graphs, from 0",
    ),
    col("sequence", &["sequence"], Text, "", "rule sequence"),
    col("level", &["level"], Int, "", "rule applications"),
    col(
        "internal_vertices",
        &["internal_vertices"],
        Int,
        "",
        "internal vertices N",
    ),
    col(
        "candidate",
        &["candidate"],
        Int,
        "",
        "gripping candidate 1-3",
    ),
    col(
        "gripping_vertex",
        &["gripping_vertex"],
        Int,
        "",
        "the gripping vertex's number",
    ),
    col(
        "modes",
        &["modes"],
        Joined,
        "",
        "up/down per internal vertex in extension order, joined by ','",
    ),
    col(
        "objective",
        &["objective"],
        Float,
        "squared paper units",
        "Ω* (Eq. 37/38)",
    ),
    col(
        "feasible",
        &["feasible"],
        Bool,
        "",
        "constraints ψ hold at the optimum",
    ),
    col(
        "max_violation",
        &["max_violation"],
        Float,
        "as the constraint",
        "largest constraint violation",
    ),
    col(
        "min_slack",
        &["min_slack"],
        Float,
        "as the constraint",
        "smallest constraint slack",
    ),
    col(
        "meets_target",
        &["meets_target"],
        Bool,
        "",
        "feasible and Ω* ≤ threshold",
    ),
    col(
        "self_intersection_free",
        &["self_intersection_free"],
        Bool,
        "",
        "null: not checked",
    ),
    col(
        "self_intersection",
        &["self_intersection"],
        Json,
        "",
        "JSON: the first self-intersection found",
    ),
    col(
        "layout_defect",
        &["layout_defect"],
        Text,
        "",
        "why the flat layout is invalid",
    ),
    col(
        "obstacle_free",
        &["obstacle_free"],
        Bool,
        "",
        "null: not checked",
    ),
    col(
        "obstacle_hit",
        &["obstacle_hit"],
        Json,
        "",
        "JSON: the first obstacle hit found",
    ),
    col(
        "verification_isometry_max",
        &["verification", "isometry_max"],
        Float,
        "relative length",
        "largest isometry error over the sweep",
    ),
    col(
        "verification_closure_max",
        &["verification", "closure_max"],
        Float,
        "paper units",
        "largest loop-closure error",
    ),
    col(
        "verification_developability_max",
        &["verification", "developability_max"],
        Float,
        "rad",
        "largest developability error (sector sum − 2π)",
    ),
    col(
        "verification_fold_angle_max",
        &["verification", "fold_angle_max"],
        Float,
        "rad",
        "largest fold-angle disagreement",
    ),
    col(
        "verification_states",
        &["verification", "states"],
        Int,
        "",
        "states swept",
    ),
    col(
        "verification_rigid_states",
        &["verification", "rigid_states"],
        Int,
        "",
        "states that are rigid",
    ),
    col(
        "verification_rigid_at_tmax",
        &["verification", "rigid_at_tmax"],
        Bool,
        "",
        "rigid at t_max (the thesis's test)",
    ),
    col(
        "verification_rigid_over_motion",
        &["verification", "rigid_over_motion"],
        Bool,
        "",
        "rigid over the whole motion",
    ),
    col(
        "verification_min_margin",
        &["verification", "min_margin"],
        Float,
        "rad",
        "smallest rigid margin (Eq. 25)",
    ),
    col(
        "verification_min_margin_t",
        &["verification", "min_margin_t"],
        Float,
        "t (motion parameter)",
        "where it occurs",
    ),
    col(
        "verification_failed",
        &["verification_failed"],
        Bool,
        "",
        "verification found a bug",
    ),
    col(
        "robust_accepted",
        &["robust_accepted"],
        Bool,
        "",
        "the optimizer's robustness block accepted (null: --post-check-only)",
    ),
    col(
        "robust_attempts",
        &["robust_attempts"],
        Int,
        "",
        "starts with a robustness phase",
    ),
    col(
        "robustness_score",
        &["robustness", "score"],
        Float,
        "",
        "smallest margin divided by its setting (the ranking)",
    ),
];

/// The columns after the margins.
const TAIL: &[Column] = &[
    col(
        "short_of_margins",
        &["short_of_margins"],
        Json,
        "",
        "JSON list: the required margins that fall short",
    ),
    col(
        "variables",
        &["variables"],
        Json,
        "paper units and rad",
        "JSON object: free variables at the optimum by name",
    ),
    col(
        "starts_run",
        &["starts_run"],
        Int,
        "",
        "starting points run",
    ),
    col(
        "warm_start",
        &["warm_start"],
        Bool,
        "",
        "the optimum came from a warm start at the parent's optimum (guided search)",
    ),
    col(
        "evaluations",
        &["evaluations"],
        Int,
        "",
        "model evaluations",
    ),
    col(
        "optimize_ms",
        &["optimize_ms"],
        Float,
        "ms (CPU)",
        "optimizing, the worker thread's CPU time",
    ),
    col(
        "check_ms",
        &["check_ms"],
        Float,
        "ms (CPU)",
        "checking and verifying, CPU time",
    ),
    col(
        "cycle",
        &["cycle"],
        Json,
        "",
        "JSON: cyclic graphs' compatibility and simulation verdict",
    ),
    col(
        "simulation",
        &["simulation"],
        Json,
        "",
        "JSON: designs with a driven central facet: the bar-and-hinge simulation against the PTU",
    ),
    col(
        "requirements",
        &["requirements"],
        Json,
        "",
        "JSON: the task's requirements judged on the sweep",
    ),
    col(
        "other",
        &[],
        Json,
        "",
        "JSON object: record fields no other column holds (null: none)",
    ),
];

/// Every column, in the file's order.
pub fn columns() -> Vec<Column> {
    let mut all = HEAD.to_vec();
    all.extend(MARGINS.iter().flatten());
    all.extend_from_slice(TAIL);
    all
}

/// The Parquet message type of [`columns`]: every column optional (null where the record
/// has no value).
fn message_type(cols: &[Column]) -> String {
    let fields: String = cols
        .iter()
        .map(|c| {
            let ty = match c.kind {
                Text | Json | Joined => "BYTE_ARRAY",
                Int => "INT64",
                Float => "DOUBLE",
                Bool => "BOOLEAN",
            };
            let ann = if ty == "BYTE_ARRAY" { " (UTF8)" } else { "" };
            format!("  OPTIONAL {ty} {}{ann};\n", c.name)
        })
        .collect();
    format!("message alternatives {{\n{fields}}}")
}

/// The value at `path` in `v`, if any (JSON null counts as none).
fn at<'a>(v: &'a Value, path: &[&str]) -> Option<&'a Value> {
    let mut v = v;
    for p in path {
        v = v.get(p)?;
    }
    (!v.is_null()).then_some(v)
}

/// A cell: a column's value for one record.
#[derive(Clone, Debug, PartialEq)]
enum Cell {
    Null,
    Text(String),
    Int(i64),
    Float(f64),
    Bool(bool),
}

/// `v` as a cell of `kind`; `None` when it does not fit.
fn cell(kind: Kind, v: &Value) -> Option<Cell> {
    Some(match kind {
        Text => Cell::Text(v.as_str()?.to_string()),
        Int => Cell::Int(v.as_i64()?),
        Float => Cell::Float(v.as_f64()?),
        Bool => Cell::Bool(v.as_bool()?),
        Json => Cell::Text(v.to_string()),
        Joined => {
            let parts: Option<Vec<&str>> = v.as_array()?.iter().map(|s| s.as_str()).collect();
            let parts = parts?;
            // A part holding ',' (or an empty list, which reads back as "") cannot be
            // split back: it goes to `other`.
            if parts.is_empty() || parts.iter().any(|p| p.contains(',') || p.is_empty()) {
                return None;
            }
            Cell::Text(parts.join(","))
        }
    })
}

/// The cells of one record (`v`, with `rec` the same record typed), in column order.
fn row(cols: &[Column], v: &Value, rec: &AlternativeRecord) -> Vec<Cell> {
    let Some(obj) = v.as_object() else {
        return vec![Cell::Null; cols.len()];
    };
    // A top-level field whose every value fits a column is held by the columns; any other
    // goes whole into `other`.
    let other: Map<String, Value> = obj
        .iter()
        .filter(|(k, x)| !fits(cols, &[k.as_str()], x))
        .map(|(k, x)| (k.clone(), x.clone()))
        .collect();
    cols.iter()
        .map(|c| match c.name {
            "id" => Cell::Text(rec.id()),
            "design" => Cell::Bool(rec.feasible_design()),
            "other" if other.is_empty() => Cell::Null,
            "other" => Cell::Text(Value::Object(other.clone()).to_string()),
            _ if other.contains_key(c.path[0]) => Cell::Null,
            _ => at(v, c.path)
                .and_then(|x| cell(c.kind, x))
                .unwrap_or(Cell::Null),
        })
        .collect()
}

/// Whether the value `x` at `path` is held by the columns exactly: null, the value of a
/// column of that path that fits its type, or an object whose every field is.
fn fits(cols: &[Column], path: &[&str], x: &Value) -> bool {
    if x.is_null() {
        return true;
    }
    if let Some(c) = cols.iter().find(|c| c.path == path) {
        return cell(c.kind, x).is_some();
    }
    let below = cols.iter().any(|c| c.path.starts_with(path));
    match x {
        Value::Object(m) if below => m.iter().all(|(k, y)| {
            let mut p = path.to_vec();
            p.push(k.as_str());
            fits(cols, &p, y)
        }),
        _ => false,
    }
}

/// Write `OUT/alternatives.parquet` from `OUT/alternatives.jsonl` (both listed in the
/// manifest first, with the temporary file): the number of records.
pub fn write_results(dir: &OutputDir) -> Result<usize, SearchError> {
    let tmp = format!("{PARQUET}.tmp");
    dir.register([dir.path(PARQUET), dir.path(&tmp)])?;
    write_parquet(&dir.path(RECORDS), &dir.path(&tmp), &dir.path(PARQUET))
}

/// Write `OUT/alternatives.parquet` (`out`) from the records file `records`: one row per
/// line, in order. Written to `tmp` first and renamed, so a killed run never leaves a
/// torn file under the final name.
pub fn write_parquet(records: &Path, tmp: &Path, out: &Path) -> Result<usize, SearchError> {
    let io = |p: &Path| {
        let path = p.display().to_string();
        move |source| SearchError::Io { path, source }
    };
    let pq = |e: ::parquet::errors::ParquetError| SearchError::Export(format!("{PARQUET}: {e}"));
    let cols = columns();
    let schema = Arc::new(parse_message_type(&message_type(&cols)).map_err(pq)?);
    let meta: Vec<Value> = cols
        .iter()
        .map(|c| {
            serde_json::json!({
                "name": c.name, "path": c.path, "kind": format!("{:?}", c.kind).to_lowercase(),
                "unit": c.unit, "doc": c.doc,
            })
        })
        .collect();
    let props = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_key_value_metadata(Some(vec![
            KeyValue::new("foldsynth:columns".into(), Value::from(meta).to_string()),
            KeyValue::new(
                "foldsynth:version".into(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
        ]))
        .build();
    let file = File::create(tmp).map_err(io(tmp))?;
    let mut writer = SerializedFileWriter::new(file, schema, Arc::new(props)).map_err(pq)?;
    let reader = BufReader::new(File::open(records).map_err(io(records))?);
    let mut rows: Vec<Vec<Cell>> = Vec::with_capacity(ROW_GROUP);
    let mut count = 0;
    for (i, line) in reader.lines().enumerate() {
        let line = line.map_err(io(records))?;
        if line.trim().is_empty() {
            continue;
        }
        let bad = |message: String| SearchError::Records {
            path: records.display().to_string(),
            line: i + 1,
            message,
        };
        let v: Value = serde_json::from_str(&line).map_err(|e| bad(e.to_string()))?;
        let rec: AlternativeRecord =
            serde_json::from_value(v.clone()).map_err(|e| bad(e.to_string()))?;
        rows.push(row(&cols, &v, &rec));
        count += 1;
        if rows.len() == ROW_GROUP {
            write_group(&mut writer, &cols, &rows).map_err(pq)?;
            rows.clear();
        }
    }
    if !rows.is_empty() || count == 0 {
        write_group(&mut writer, &cols, &rows).map_err(pq)?;
    }
    writer.close().map_err(pq)?;
    std::fs::rename(tmp, out).map_err(io(out))?;
    Ok(count)
}

/// Write `rows` as one row group.
fn write_group(
    writer: &mut SerializedFileWriter<File>,
    cols: &[Column],
    rows: &[Vec<Cell>],
) -> ::parquet::errors::Result<()> {
    let mut group = writer.next_row_group()?;
    let mut k = 0;
    while let Some(mut w) = group.next_column()? {
        let cells = rows.iter().map(|r| &r[k]);
        let def: Vec<i16> = cells.clone().map(|c| i16::from(*c != Cell::Null)).collect();
        match cols[k].kind {
            Text | Json | Joined => {
                let v: Vec<ByteArray> = cells
                    .filter_map(|c| match c {
                        Cell::Text(s) => Some(ByteArray::from(s.as_bytes().to_vec())),
                        _ => None,
                    })
                    .collect();
                w.typed::<ByteArrayType>()
                    .write_batch(&v, Some(&def), None)?;
            }
            Int => {
                let v: Vec<i64> = cells
                    .filter_map(|c| if let Cell::Int(x) = c { Some(*x) } else { None })
                    .collect();
                w.typed::<Int64Type>().write_batch(&v, Some(&def), None)?;
            }
            Float => {
                let v: Vec<f64> = cells
                    .filter_map(|c| {
                        if let Cell::Float(x) = c {
                            Some(*x)
                        } else {
                            None
                        }
                    })
                    .collect();
                w.typed::<DoubleType>().write_batch(&v, Some(&def), None)?;
            }
            Bool => {
                let v: Vec<bool> = cells
                    .filter_map(|c| {
                        if let Cell::Bool(x) = c {
                            Some(*x)
                        } else {
                            None
                        }
                    })
                    .collect();
                w.typed::<BoolType>().write_batch(&v, Some(&def), None)?;
            }
        }
        w.close()?;
        k += 1;
    }
    group.close()?;
    Ok(())
}

/// Set `v` at `path` in `obj`, making the objects on the way.
fn put(obj: &mut Map<String, Value>, path: &[&str], v: Value) {
    let (last, rest) = path.split_last().expect("a column's path is not empty");
    let mut o = obj;
    for p in rest {
        let next = o
            .entry(p.to_string())
            .or_insert_with(|| Value::Object(Map::new()));
        if !next.is_object() {
            *next = Value::Object(Map::new());
        }
        o = next.as_object_mut().expect("made an object above");
    }
    o.insert(last.to_string(), v);
}

/// The rows of a results file written by [`write_parquet`], one JSON object per row
/// keyed by column name (null cells left out; JSON columns as their text).
pub fn read_rows(path: &Path) -> Result<Vec<Map<String, Value>>, String> {
    let shown = path.display();
    let file = File::open(path).map_err(|e| format!("{shown}: {e}"))?;
    let reader = SerializedFileReader::new(file).map_err(|e| format!("{shown}: {e}"))?;
    let rows = reader
        .get_row_iter(None)
        .map_err(|e| format!("{shown}: {e}"))?;
    let mut out = Vec::new();
    for row in rows {
        let row = row.map_err(|e| format!("{shown}: {e}"))?;
        let mut obj = Map::new();
        for (name, field) in row.get_column_iter() {
            let v = match field {
                Field::Null => continue,
                Field::Bool(b) => Value::Bool(*b),
                Field::Long(x) => Value::from(*x),
                Field::Double(x) => Value::from(*x),
                Field::Str(s) => Value::from(s.as_str()),
                other => return Err(format!("{shown}: column {name}: unexpected {other:?}")),
            };
            obj.insert(name.clone(), v);
        }
        out.push(obj);
    }
    Ok(out)
}

/// The records in a results file written by [`write_parquet`], as the JSON objects of the
/// JSONL lines they came from (the derived columns left out; a record's absent optional
/// fields are absent or null).
pub fn read_records(path: &Path) -> Result<Vec<Value>, String> {
    let shown = path.display();
    let cols = columns();
    let mut out = Vec::new();
    for row in read_rows(path)? {
        let mut obj = Map::new();
        for (name, v) in row {
            let Some(c) = cols.iter().find(|c| c.name == name) else {
                return Err(format!("{shown}: column {name} is not foldsynth's"));
            };
            let v = match (c.kind, v) {
                (Json, Value::String(s)) => {
                    serde_json::from_str(&s).map_err(|e| format!("{shown}: column {name}: {e}"))?
                }
                (Joined, Value::String(s)) => {
                    Value::from(s.split(',').map(Value::from).collect::<Vec<_>>())
                }
                (_, v) => v,
            };
            match c.name {
                "id" | "design" => {}
                "other" => {
                    if let Value::Object(m) = v {
                        obj.extend(m);
                    }
                }
                _ => put(&mut obj, c.path, v),
            }
        }
        out.push(Value::Object(obj));
    }
    Ok(out)
}
