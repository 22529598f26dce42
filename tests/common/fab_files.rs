//! The files of a thick design (`foldsynth fabricate`, or a search with `[fabrication]`)
//! read back by independent readers: ezdxf for the DXF plies, trimesh for STL and 3MF,
//! from the repository's `.venv` or python3 (`FOLDSYNTH_REQUIRE_FAB_TOOLS=1` makes their
//! absence a failure), and judged against the folder's own `fabrication.json`.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Reads a folder's plies and solids; prints one JSON object.
const READER: &str = r#"
import json, sys, zipfile, ezdxf, trimesh
out = sys.argv[1]
rec = json.load(open(out + "/fabrication.json"))
bill = rec["fabrication"]
names = ["rigid", "hinge"] if bill["sides"] == "one" else ["top", "bottom", "hinge"]
xy = lambda p: [float(p[0]), float(p[1])]
plies = {}
for ply in names:
    doc = ezdxf.readfile(f"{out}/ply-{ply}.dxf")
    msp = doc.modelspace()
    plies[ply] = {
        "version": doc.dxfversion,
        "layers": sorted(l.dxf.name for l in doc.layers),
        "cut": [{"closed": bool(e.is_closed), "points": [xy(v.dxf.location) for v in e.vertices]}
                for e in msp.query("POLYLINE[layer=='CUT']")],
        "cut_lines": [[xy(e.dxf.start), xy(e.dxf.end)] for e in msp.query("LINE[layer=='CUT']")],
        "circles": [xy(e.dxf.center) + [float(e.dxf.radius)] for e in msp.query("CIRCLE[layer=='CUT']")],
        "register": [[xy(e.dxf.start), xy(e.dxf.end)] for e in msp.query("LINE[layer=='REGISTER']")],
        "labels": [t.dxf.text for t in msp.query("TEXT")],
        "lines": {l: len(msp.query(f"LINE[layer=='{l}']")) for l in ["SCORE", "MOUNTAIN", "VALLEY"]},
    }
def meshes_3mf(path):
    # trimesh's own 3MF reader: it finds the model at 3D/3dmodel.model, the part name our
    # archives use (threemf writes 3D/model.model; export::print re-packs it).
    assert "3D/3dmodel.model" in zipfile.ZipFile(path).namelist()
    scene = trimesh.load(path)
    meshes = list(scene.dump()) if isinstance(scene, trimesh.Scene) else [scene]
    return [trimesh.Trimesh(vertices=m.vertices, faces=m.faces, process=True) for m in meshes]
solids = {}
for p in bill["panels"]:
    k = p["facet"]
    m = trimesh.load(f"{out}/panel-{k}.stl", force="mesh")
    solids[f"panel-{k}.stl"] = [bool(m.is_watertight), bool(m.is_winding_consistent), float(m.volume)]
    (m,) = meshes_3mf(f"{out}/panel-{k}.3mf")
    solids[f"panel-{k}.3mf"] = [bool(m.is_watertight), bool(m.is_winding_consistent), float(m.volume)]
for st in rec["states"]:
    solids[f"assembly-{st['name']}.3mf"] = [[bool(g.is_watertight), float(g.volume)]
                                           for g in meshes_3mf(f"{out}/assembly-{st['name']}.3mf")]
print(json.dumps({"plies": plies, "solids": solids}))
"#;

/// Python with ezdxf and trimesh: the repository's .venv first, then python3.
pub fn python() -> Option<PathBuf> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    [venv, PathBuf::from("python3")].into_iter().find(|py| {
        Command::new(py)
            .args(["-c", "import ezdxf, trimesh, networkx, lxml"])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// The folder's `fabrication.json`.
pub fn record(out: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("fabrication.json")).unwrap()).unwrap()
}

/// What the independent readers found in the folder `out`; `None` (skipped, said on
/// stderr) when Python lacks them, unless `FOLDSYNTH_REQUIRE_FAB_TOOLS=1`.
pub fn read_back(out: &Path) -> Option<Value> {
    let Some(py) = python() else {
        let msg = "python with ezdxf, trimesh, networkx and lxml not found: DXF/STL/3MF not read back independently";
        assert!(
            std::env::var("FOLDSYNTH_REQUIRE_FAB_TOOLS").as_deref() != Ok("1"),
            "{msg} (FOLDSYNTH_REQUIRE_FAB_TOOLS=1)"
        );
        eprintln!("skipped: {msg}");
        return None;
    };
    let o = Command::new(py)
        .args(["-c", READER, out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    Some(serde_json::from_slice(&o.stdout).unwrap())
}

/// `v` as a point.
pub fn pt(v: &Value) -> [f64; 2] {
    [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()]
}

/// The folder's files read back independently and judged against its `fabrication.json`:
/// every ply DXF R12 with every layer; each rigid ply's closed cuts the panels' outlines
/// at its outer face (the bill's, in mm, moved by the layout's offset) and the sheet's
/// outline (without kerf and tabs); a label per panel, a score line per crease; the hinge
/// ply's creases; every panel solid closed, consistently wound, of positive volume, and
/// every assembly one such part per panel. The reader's output (`None`: skipped).
pub fn independent_readers(out: &Path) -> Option<Value> {
    let rec = record(out);
    let r = read_back(out)?;
    let bill = &rec["fabrication"];
    let lam = &rec["laminate"];
    let offset = pt(&lam["offset_mm"]);
    let panels = bill["panels"].as_array().unwrap();
    let creases = bill["creases"].as_array().unwrap().len();
    let plies = r["plies"].as_object().unwrap();
    for (name, ply) in plies {
        assert_eq!(ply["version"], "AC1009", "{name}: DXF R12");
        for l in ["CUT", "SCORE", "MOUNTAIN", "VALLEY", "LABEL", "REGISTER"] {
            assert!(
                ply["layers"].as_array().unwrap().iter().any(|x| x == l),
                "{name}: no layer {l}"
            );
        }
        assert_eq!(ply["circles"].as_array().unwrap().len(), 3, "{name}: holes");
        assert_eq!(
            ply["register"].as_array().unwrap().len(),
            8,
            "{name}: crosses"
        );
        if name == "hinge" {
            let folds = ply["lines"]["MOUNTAIN"].as_u64().unwrap()
                + ply["lines"]["VALLEY"].as_u64().unwrap();
            assert_eq!(
                folds as usize, creases,
                "hinge ply: one fold line per crease"
            );
            continue;
        }
        assert_eq!(
            ply["labels"].as_array().unwrap().len(),
            panels.len(),
            "{name}"
        );
        assert_eq!(
            ply["lines"]["SCORE"].as_u64().unwrap() as usize,
            creases,
            "{name}"
        );
        if lam["kerf_mm"] != 0.0 || lam["tab_width_mm"] != 0.0 {
            continue;
        }
        let cut = ply["cut"].as_array().unwrap();
        assert_eq!(cut.len(), panels.len() + 1, "{name}: panels and the sheet");
        for (panel, poly) in panels.iter().zip(cut) {
            let layers = panel["layers"].as_array().unwrap();
            let layer = if name == "bottom" {
                &layers[0]
            } else {
                &layers[layers.len() - 1]
            };
            let want = layer["outline_mm"].as_array().unwrap();
            let got = poly["points"].as_array().unwrap();
            assert_eq!(poly["closed"], true);
            assert_eq!(got.len(), want.len(), "{name}: P{}", panel["facet"]);
            for (w, g) in want.iter().zip(got) {
                let (w, g) = (pt(w), pt(g));
                for k in 0..2 {
                    assert!(
                        (w[k] + offset[k] - g[k]).abs() < 1e-9,
                        "{name}: {w:?} vs {g:?}"
                    );
                }
            }
        }
    }
    for (name, v) in r["solids"].as_object().unwrap() {
        if name.starts_with("panel-") {
            assert_eq!(v[0], true, "{name}: not watertight");
            assert_eq!(v[1], true, "{name}: winding");
            assert!(v[2].as_f64().unwrap() > 0.0, "{name}: volume");
        } else {
            let parts = v.as_array().unwrap();
            assert_eq!(parts.len(), panels.len(), "{name}");
            for p in parts {
                assert!(p[0] == true && p[1].as_f64().unwrap() > 0.0, "{name}: {p}");
            }
        }
    }
    Some(r)
}
