//! Making inputs: structure-aware mutations (TOML and JSON value trees of the seeds,
//! grammar generators for the notations) and byte-level mutations of the seeds.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::{Target, generate, seeds};

/// Largest input made (a few are larger by a deep nesting insert).
const MAX_LEN: usize = 256 << 10;

/// Tokens worth inserting anywhere.
const TOKENS: [&str; 40] = [
    "1e308",
    "-1e308",
    "1e309",
    "nan",
    "inf",
    "-inf",
    "NaN",
    "Infinity",
    "5e-324",
    "0",
    "-0",
    "18446744073709551616",
    "-9223372036854775809",
    "4294967296",
    "\"\"",
    "[]",
    "{}",
    "null",
    "true",
    "\"pi\"",
    "t",
    "(",
    ")",
    ",",
    "\"../..\"",
    "\"/etc/passwd\"",
    "\\u0000",
    "\n",
    "\"",
    "'",
    "=",
    "[[",
    "]]",
    "#",
    "\u{202e}",
    "é",
    "∅",
    "χ",
    "\"x\" = 1\n",
    "1e-400",
];

/// Strings worth putting into a value.
const STRINGS: [&str; 22] = [
    "",
    "pi",
    "t",
    "-t",
    "1/0",
    "0/0",
    "sqrt(-1)",
    "../../victim",
    "/abs/path",
    "a/b",
    "B",
    "M",
    "V",
    "C",
    "creasePattern",
    "foldedForm",
    "up",
    "down",
    "extendable",
    "terminal",
    "pi/0",
    "((((((((((((t))))))))))))",
];

/// Keys the formats use (for inserting fields).
const KEYS: [&str; 26] = [
    "vertices_coords",
    "edges_vertices",
    "faces_vertices",
    "edges_assignment",
    "edges_foldAngle",
    "frame_classes",
    "file_frames",
    "frame_parent",
    "frame_inherit",
    "foldsynth:t",
    "edges_foldsynth:driven",
    "pattern",
    "meta",
    "frames",
    "coords",
    "fold_angles",
    "name",
    "n_max",
    "xy",
    "type",
    "drive",
    "states",
    "t_max",
    "rotations",
    "steps",
    "key",
];

/// Numbers worth putting into a value.
const FLOATS: [f64; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    1e-9,
    1e-300,
    5e-324,
    1e6,
    1e7,
    1e15,
    1e308,
    -1e308,
    f64::MAX,
    180.0,
    std::f64::consts::PI,
];

const INTEGERS: [i64; 12] = [
    0,
    1,
    -1,
    2,
    3,
    6,
    7,
    1000,
    4_000_000_000,
    i64::MAX,
    i64::MIN,
    1 << 40,
];

/// One input for `target`.
pub fn make(target: Target, rng: &mut ChaCha8Rng) -> Vec<u8> {
    let all = seeds::of(target);
    let seed = &all[rng.random_range(0..all.len())];
    match rng.random_range(0..10) {
        0..=3 => structured(target, seed, rng),
        4..=7 => bytes(seed, all, rng),
        8 => bytes(&structured(target, seed, rng), all, rng),
        _ => match target {
            Target::Vertex => generate::vertex(rng).into_bytes(),
            Target::Expr => generate::expr(rng, 6).into_bytes(),
            _ => seed.clone(),
        },
    }
}

/// A structure-aware mutation of `seed` (a generated input for the notations).
fn structured(target: Target, seed: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    match target {
        Target::Vertex => generate::vertex(rng).into_bytes(),
        Target::Expr => generate::expr(rng, 5).into_bytes(),
        Target::Task | Target::Pattern => toml_tree(seed, rng),
        Target::Fold | Target::Design => json_tree(seed, rng),
        Target::Records => records(seed, rng),
        Target::Mesh => mesh(seed, rng),
    }
}

/// A mutation of a mesh file that keeps its form: a binary STL's triangle count rewritten
/// (the reader must not trust it), or lines of a text file repeated, dropped or given an
/// interesting number.
fn mesh(seed: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    if b.len() >= 84 && !b.starts_with(b"solid") {
        let counts = [0, 1, 3, 5, 19_999, 20_001, 1 << 24, u32::MAX];
        let n = counts[rng.random_range(0..counts.len())];
        b[80..84].copy_from_slice(&n.to_le_bytes());
        if rng.random_bool(0.5) {
            let len = b.len();
            b.truncate(rng.random_range(84..=len));
        }
        return b;
    }
    let mut lines: Vec<Vec<u8>> = b.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
    for _ in 0..rng.random_range(1..4) {
        let i = rng.random_range(0..lines.len());
        match rng.random_range(0..3) {
            0 => {
                let line = lines[i].clone();
                let times = rng.random_range(1..64);
                lines.splice(i..i, std::iter::repeat_n(line, times));
            }
            1 if lines.len() > 1 => {
                lines.remove(i);
            }
            _ => {
                let words: Vec<&[u8]> = lines[i].split(|&c| c == b' ').collect();
                let j = rng.random_range(0..words.len());
                let n = generate::NUMBERS[rng.random_range(0..generate::NUMBERS.len())];
                let mut out: Vec<Vec<u8>> = words.iter().map(|w| w.to_vec()).collect();
                out[j] = n.as_bytes().to_vec();
                lines[i] = out.join(&b' ');
            }
        }
    }
    lines.join(&b'\n')
}

/// A step of a path into a value tree.
enum Step {
    Index(usize),
    Key(String),
}

/// A parsed document the structured mutations walk: a JSON or a TOML value. The walk and
/// the mutations are written once over this; each format says how its nodes look.
trait Tree: Clone + Sized {
    /// Chance of stopping at each level of a random path.
    const STOP: f64;
    /// Most array levels one nesting mutation wraps a node in.
    const NEST: usize;
    /// The node's elements when it is an array.
    fn items(&self) -> Option<&Vec<Self>>;
    /// The node's elements when it is an array, to change.
    fn items_mut(&mut self) -> Option<&mut Vec<Self>>;
    /// The node's entries when it is a table/object, in order.
    fn entries(&self) -> Option<Vec<(&String, &Self)>>;
    /// The entry `key` of a table/object.
    fn entry_mut(&mut self, key: &str) -> Option<&mut Self>;
    /// Remove the entry `key` (tables/objects only).
    fn remove_key(&mut self, key: &str);
    /// Insert `value` at `key` (tables/objects only).
    fn insert_key(&mut self, key: &str, value: Self);
    /// A random value, often one that is out of range somewhere.
    fn random(rng: &mut ChaCha8Rng) -> Self;
    /// Scale a number by a factor that breaks it (other nodes stay).
    fn scale(&mut self, rng: &mut ChaCha8Rng);
    /// Wrap the node in a one-element array.
    fn nest(&mut self);
}

impl Tree for serde_json::Value {
    const STOP: f64 = 0.25;
    const NEST: usize = 200;
    fn items(&self) -> Option<&Vec<Self>> {
        self.as_array()
    }
    fn items_mut(&mut self) -> Option<&mut Vec<Self>> {
        self.as_array_mut()
    }
    fn entries(&self) -> Option<Vec<(&String, &Self)>> {
        self.as_object().map(|o| o.iter().collect())
    }
    fn entry_mut(&mut self, key: &str) -> Option<&mut Self> {
        self.as_object_mut()?.get_mut(key)
    }
    fn remove_key(&mut self, key: &str) {
        if let Some(o) = self.as_object_mut() {
            o.remove(key);
        }
    }
    fn insert_key(&mut self, key: &str, value: Self) {
        if let Some(o) = self.as_object_mut() {
            o.insert(key.into(), value);
        }
    }
    fn random(rng: &mut ChaCha8Rng) -> Self {
        use serde_json::{Value, json};
        match rng.random_range(0..9) {
            0 | 1 => json!(FLOATS[rng.random_range(0..FLOATS.len())]),
            2 => json!(INTEGERS[rng.random_range(0..INTEGERS.len())]),
            3 => json!(STRINGS[rng.random_range(0..STRINGS.len())]),
            4 => Value::Null,
            5 => json!(rng.random_bool(0.5)),
            6 => json!([]),
            7 => json!({}),
            _ => {
                let n = rng.random_range(0..5);
                Value::Array((0..n).map(|_| json!(rng.random_range(-3.0..3.0))).collect())
            }
        }
    }
    fn scale(&mut self, rng: &mut ChaCha8Rng) {
        if let Some(x) = self.as_f64() {
            let f = [-1.0, 1e6, 1e-6, 1.0 + 1e-7, 0.0, 2.0][rng.random_range(0..6)];
            if let Some(n) = serde_json::Number::from_f64(x * f) {
                *self = serde_json::Value::Number(n);
            }
        }
    }
    fn nest(&mut self) {
        *self = serde_json::Value::Array(vec![self.take()]);
    }
}

impl Tree for toml::Value {
    const STOP: f64 = 0.2;
    const NEST: usize = 100;
    fn items(&self) -> Option<&Vec<Self>> {
        self.as_array()
    }
    fn items_mut(&mut self) -> Option<&mut Vec<Self>> {
        self.as_array_mut()
    }
    fn entries(&self) -> Option<Vec<(&String, &Self)>> {
        self.as_table().map(|t| t.iter().collect())
    }
    fn entry_mut(&mut self, key: &str) -> Option<&mut Self> {
        self.as_table_mut()?.get_mut(key)
    }
    fn remove_key(&mut self, key: &str) {
        if let Some(t) = self.as_table_mut() {
            t.remove(key);
        }
    }
    fn insert_key(&mut self, key: &str, value: Self) {
        if let Some(t) = self.as_table_mut() {
            t.insert(key.into(), value);
        }
    }
    fn random(rng: &mut ChaCha8Rng) -> Self {
        use toml::Value;
        match rng.random_range(0..9) {
            0 => Value::Float(FLOATS[rng.random_range(0..FLOATS.len())]),
            1 => Value::Float([f64::NAN, f64::INFINITY, f64::NEG_INFINITY][rng.random_range(0..3)]),
            2 => Value::Integer(INTEGERS[rng.random_range(0..INTEGERS.len())]),
            3 => Value::String(STRINGS[rng.random_range(0..STRINGS.len())].into()),
            4 => Value::Boolean(rng.random_bool(0.5)),
            5 => Value::Array(Vec::new()),
            6 => Value::Table(toml::Table::new()),
            7 => Value::String("x".repeat(rng.random_range(100..20_000))),
            _ => {
                let n = rng.random_range(0..5);
                Value::Array(
                    (0..n)
                        .map(|_| Value::Float(rng.random_range(-3.0..3.0)))
                        .collect(),
                )
            }
        }
    }
    fn scale(&mut self, rng: &mut ChaCha8Rng) {
        match self {
            toml::Value::Float(x) => {
                *x *= [-1.0, 1e6, 1e-6, 1.0 + 1e-7, 0.0][rng.random_range(0..5)]
            }
            toml::Value::Integer(i) => {
                *i = i.wrapping_mul([-1, 1000, 0, 2, 1 << 20][rng.random_range(0..5)])
            }
            _ => {}
        }
    }
    fn nest(&mut self) {
        let inner = std::mem::replace(self, toml::Value::Boolean(false));
        *self = toml::Value::Array(vec![inner]);
    }
}

/// A random path from `v` down its arrays and tables.
fn random_path<T: Tree>(mut v: &T, rng: &mut ChaCha8Rng) -> Vec<Step> {
    let mut path = Vec::new();
    loop {
        if rng.random_bool(T::STOP) {
            return path;
        }
        if let Some(a) = v.items().filter(|a| !a.is_empty()) {
            let i = rng.random_range(0..a.len());
            path.push(Step::Index(i));
            v = &a[i];
        } else if let Some(e) = v.entries().filter(|e| !e.is_empty()) {
            let (k, next) = e[rng.random_range(0..e.len())];
            path.push(Step::Key(k.clone()));
            v = next;
        } else {
            return path;
        }
    }
}

/// The node at `path`, if the tree still has it.
fn node_at<'a, T: Tree>(mut v: &'a mut T, path: &[Step]) -> Option<&'a mut T> {
    for s in path {
        v = match s {
            Step::Index(i) => v.items_mut()?.get_mut(*i)?,
            Step::Key(k) => v.entry_mut(k)?,
        };
    }
    Some(v)
}

/// One mutation of `node`: replaced, an element dropped, duplicated or cut off, an entry
/// dropped or added, a number broken, or the node nested deep.
fn mutate_node<T: Tree>(node: &mut T, rng: &mut ChaCha8Rng) {
    match rng.random_range(0..9) {
        0 | 1 => *node = T::random(rng),
        2 => {
            if let Some(a) = node.items_mut().filter(|a| !a.is_empty()) {
                let i = rng.random_range(0..a.len());
                a.remove(i);
            }
        }
        3 => {
            if let Some(a) = node.items_mut().filter(|a| !a.is_empty() && a.len() < 5000) {
                let i = rng.random_range(0..a.len());
                let x = a[i].clone();
                a.insert(i, x);
            }
        }
        4 => {
            let key = node
                .entries()
                .filter(|e| !e.is_empty())
                .map(|e| e[rng.random_range(0..e.len())].0.clone());
            if let Some(k) = key {
                node.remove_key(&k);
            }
        }
        5 => {
            let key = KEYS[rng.random_range(0..KEYS.len())];
            let value = T::random(rng);
            node.insert_key(key, value);
        }
        6 => node.scale(rng),
        7 => {
            if let Some(a) = node.items_mut() {
                let n = rng.random_range(0..=a.len());
                a.truncate(n);
            }
        }
        _ => {
            for _ in 0..rng.random_range(1..T::NEST) {
                node.nest();
            }
        }
    }
}

/// A few mutations of `tree` at random places.
fn mutate_tree<T: Tree>(tree: &mut T, rng: &mut ChaCha8Rng) {
    for _ in 0..rng.random_range(1..5) {
        let path = random_path(tree, rng);
        if let Some(node) = node_at(tree, &path) {
            mutate_node(node, rng);
        }
    }
}

fn json_tree(seed: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let Ok(mut v) = serde_json::from_slice::<serde_json::Value>(seed) else {
        return seed.to_vec();
    };
    mutate_tree(&mut v, rng);
    serde_json::to_vec(&v).unwrap_or_else(|_| seed.to_vec())
}

fn toml_tree(seed: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let Some(mut v) = std::str::from_utf8(seed)
        .ok()
        .and_then(|s| s.parse::<toml::Table>().ok())
        .map(toml::Value::Table)
    else {
        return seed.to_vec();
    };
    mutate_tree(&mut v, rng);
    match v {
        toml::Value::Table(t) => toml::to_string(&t)
            .map(String::into_bytes)
            .unwrap_or_else(|_| seed.to_vec()),
        _ => seed.to_vec(),
    }
}

/// Records: lines mutated as JSON, repeated, dropped, reordered, torn.
fn records(seed: &[u8], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = seed
        .split(|&b| b == b'\n')
        .filter(|l| !l.is_empty())
        .map(<[u8]>::to_vec)
        .collect();
    for _ in 0..rng.random_range(1..4) {
        if lines.is_empty() {
            break;
        }
        let i = rng.random_range(0..lines.len());
        match rng.random_range(0..6) {
            0 | 1 => lines[i] = json_tree(&lines[i], rng),
            2 => {
                let l = lines[i].clone();
                lines.insert(rng.random_range(0..=lines.len()), l);
            }
            3 => {
                lines.remove(i);
            }
            4 => {
                let j = rng.random_range(0..lines.len());
                lines.swap(i, j);
            }
            _ => {
                let n = rng.random_range(0..=lines[i].len());
                lines[i].truncate(n);
            }
        }
    }
    let mut out = lines.join(&b'\n');
    if rng.random_range(0..4) != 0 {
        out.push(b'\n');
    }
    out
}

/// Byte-level mutations of `seed` (with splices from `all`).
fn bytes(seed: &[u8], all: &[Vec<u8>], rng: &mut ChaCha8Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..rng.random_range(1..7) {
        let len = b.len();
        let pos = if len == 0 {
            0
        } else {
            rng.random_range(0..=len)
        };
        match rng.random_range(0..10) {
            0 if len > 0 => {
                let i = pos.min(len - 1);
                b[i] ^= 1 << rng.random_range(0..8);
            }
            1 if len > 0 => {
                let i = pos.min(len - 1);
                b[i] = rng.random_range(0x20..0x7f);
            }
            2 | 3 => {
                let tok = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes();
                b.splice(pos..pos, tok.iter().copied());
            }
            4 => {
                let n = rng.random_range(1..32).min(len - pos);
                b.drain(pos..pos + n);
            }
            5 => {
                let n = rng.random_range(1..64).min(len - pos);
                let chunk = b[pos..pos + n].to_vec();
                b.splice(pos..pos, chunk);
            }
            6 => {
                let other = &all[rng.random_range(0..all.len())];
                let from = if other.is_empty() {
                    0
                } else {
                    rng.random_range(0..other.len())
                };
                b.truncate(pos);
                b.extend_from_slice(&other[from..]);
            }
            7 => {
                // A number replaced by an interesting one.
                if let Some(start) = (pos..len).find(|&i| b[i].is_ascii_digit()) {
                    let end = (start..len)
                        .find(|&i| !(b[i].is_ascii_digit() || b[i] == b'.'))
                        .unwrap_or(len);
                    let n = generate::NUMBERS[rng.random_range(0..generate::NUMBERS.len())];
                    b.splice(start..end, n.bytes());
                }
            }
            8 => b.truncate(pos),
            _ => {
                // Deep nesting.
                let (open, close) =
                    [(b'(', b')'), (b'[', b']'), (b'{', b'}')][rng.random_range(0..3)];
                let n = rng.random_range(1..100_000);
                let mut nest = vec![open; n];
                if rng.random_bool(0.5) {
                    nest.push(b't');
                    nest.extend(std::iter::repeat_n(close, n));
                }
                b.splice(pos..pos, nest);
            }
        }
        if b.len() > MAX_LEN && rng.random_range(0..4) != 0 {
            b.truncate(MAX_LEN);
        }
    }
    b
}
