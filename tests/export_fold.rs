//! FOLD export and reading: the file follows the FOLD spec, reads back to the same
//! geometry, and malformed files get errors that name the field.

use std::f64::consts::{FRAC_PI_2, PI};

use foldsynth::export::fold::{Assignment, EdgeFaces, FoldFile};
use foldsynth::export::verify::{VerifyOptions, verify};
use foldsynth::export::{DesignMeta, FoldSpec, Mode, samples};
use foldsynth::pattern::{EdgeKind, Pattern};
use serde_json::Value;

fn meta() -> DesignMeta {
    DesignMeta {
        task: "gripper".into(),
        rule_sequence: "2, 3, (4, 8)".into(),
        modes: vec![Mode::Up, Mode::Down],
        gripping_vertex: Some(6),
        objective: Some(3.5e-7),
        ..DesignMeta::default()
    }
}

fn fold_text(p: &Pattern, spec: FoldSpec) -> String {
    foldsynth::export::fold::to_fold_string(p, &meta(), spec).unwrap()
}

#[test]
fn written_file_has_the_spec_fields() {
    let p = samples::degree4(PI / 3.0, FRAC_PI_2, 5);
    let v: Value = serde_json::from_str(&fold_text(&p, FoldSpec::V1_2)).unwrap();
    assert_eq!(v["file_spec"], 1.2);
    assert_eq!(v["file_creator"], "foldsynth");
    assert_eq!(v["file_classes"], serde_json::json!(["singleModel"]));
    assert_eq!(v["frame_classes"], serde_json::json!(["creasePattern"]));
    // Flat coordinates are 2D.
    assert!(
        v["vertices_coords"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c.as_array().unwrap().len() == 2)
    );
    // Final fold angles in degrees, valley positive: the driven crease is a valley of 90°.
    let fa = v["edges_foldAngle"].as_array().unwrap();
    assert!((fa[0].as_f64().unwrap() - 90.0).abs() < 1e-12);
    // Assignments follow the sign of the final angle; boundary edges are B.
    let asg: Vec<&str> = v["edges_assignment"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    for (i, e) in p.edges.iter().enumerate() {
        let a = p.frames.last().unwrap().fold_angles[i];
        let expected = match e.kind {
            EdgeKind::Boundary => "B",
            _ if a > 0.0 => "V",
            _ => "M",
        };
        assert_eq!(asg[i], expected, "edge {i}");
        // Sign of edges_foldAngle matches the assignment (the spec's requirement); a
        // boundary edge has no fold angle (null, as Origami Simulator writes it, in every
        // frame: a 0 would draw the boundary invisible there, issue 20).
        match asg[i] {
            "V" => assert!(fa[i].as_f64().unwrap() > 0.0),
            "M" => assert!(fa[i].as_f64().unwrap() < 0.0),
            "B" => {
                assert!(fa[i].is_null(), "edge {i}: {}", fa[i]);
                for f in v["file_frames"].as_array().unwrap() {
                    assert!(f["edges_foldAngle"][i].is_null());
                }
            }
            _ => assert_eq!(fa[i].as_f64().unwrap(), 0.0),
        }
    }
    assert!(asg.contains(&"B"));
    // Faces are counter-clockwise in the flat state.
    let coords = v["vertices_coords"].as_array().unwrap();
    for f in v["faces_vertices"].as_array().unwrap() {
        let idx: Vec<usize> = f
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap() as usize)
            .collect();
        let pts: Vec<[f64; 2]> = idx
            .iter()
            .map(|&i| {
                [
                    coords[i][0].as_f64().unwrap(),
                    coords[i][1].as_f64().unwrap(),
                ]
            })
            .collect();
        assert!(foldsynth::geom::signed_area_2d(&pts) > 0.0);
    }
    // Folded frames.
    let frames = v["file_frames"].as_array().unwrap();
    assert_eq!(frames.len(), 5);
    for (k, f) in frames.iter().enumerate() {
        assert_eq!(f["frame_classes"], serde_json::json!(["foldedForm"]));
        assert_eq!(f["frame_parent"], 0);
        assert_eq!(f["frame_inherit"], true);
        assert!(
            f["vertices_coords"]
                .as_array()
                .unwrap()
                .iter()
                .all(|c| c.as_array().unwrap().len() == 3)
        );
        assert_eq!(f["foldsynth:t"].as_f64().unwrap(), p.frames[k].t);
        let a0 = f["edges_foldAngle"][0].as_f64().unwrap();
        assert!((a0 - p.frames[k].t.to_degrees()).abs() < 1e-12);
    }
    // Custom properties carry a colon (the spec's convention).
    assert_eq!(v["foldsynth:task"], "gripper");
    assert_eq!(v["foldsynth:ruleSequence"], "2, 3, (4, 8)");
    assert_eq!(v["foldsynth:modes"], serde_json::json!(["up", "down"]));
    assert_eq!(v["foldsynth:grippingVertex"], 6);
    assert_eq!(v["foldsynth:objective"], 3.5e-7);
    assert_eq!(v["foldsynth:frameT"].as_array().unwrap().len(), 5);
    for k in v.as_object().unwrap().keys() {
        let standard = ["file_", "frame_", "vertices_", "edges_", "faces_"]
            .iter()
            .any(|p| k.starts_with(p));
        assert!(
            standard || k.contains(':'),
            "non-standard key without a namespace: {k}"
        );
    }
    let v11: Value = serde_json::from_str(&fold_text(&p, FoldSpec::V1_1)).unwrap();
    assert_eq!(v11["file_spec"], 1.1);
}

#[test]
fn crease_flat_over_the_whole_motion_is_f() {
    let mut p = samples::single_crease(1.0, 3);
    // Pretend the driven crease never moves: it must be F, and its SVG line yellow.
    for f in &mut p.frames {
        f.fold_angles[0] = 0.0;
    }
    let v: Value = serde_json::from_str(&fold_text(&p, FoldSpec::V1_2)).unwrap();
    assert_eq!(v["edges_assignment"][0], "F");
    // Zero at the last frame but folded before: the largest angle decides.
    let mut q = samples::single_crease(1.0, 3);
    q.frames[2].fold_angles[0] = 0.0;
    q.frames[1].fold_angles[0] = -0.4;
    let v: Value = serde_json::from_str(&fold_text(&q, FoldSpec::V1_2)).unwrap();
    assert_eq!(v["edges_assignment"][0], "M");
}

fn assert_same_geometry(a: &Pattern, b: &Pattern) {
    assert_eq!(a.vertices, b.vertices);
    assert_eq!(a.edges, b.edges);
    assert_eq!(a.faces, b.faces);
    assert_eq!(a.frames.len(), b.frames.len());
    for (fa, fb) in a.frames.iter().zip(&b.frames) {
        assert_eq!(fa.t, fb.t);
        assert_eq!(fa.coords, fb.coords);
        for (x, y) in fa.fold_angles.iter().zip(&fb.fold_angles) {
            // Radians → degrees → radians may lose an ulp.
            assert!((x - y).abs() < 1e-13, "{x} vs {y}");
        }
    }
}

#[test]
fn round_trip_gives_the_same_geometry() {
    for p in [
        samples::single_crease(2.5, 7),
        samples::degree4(1.2, 2.0, 6),
        samples::single_crease(1.0, 0),
    ] {
        let text = fold_text(&p, FoldSpec::V1_2);
        let f = FoldFile::parse(&text, "roundtrip.fold").unwrap();
        assert!(!f.faces_derived && !f.edges_derived);
        assert_eq!(f.custom["foldsynth:task"], "gripper");
        let back = f.to_pattern().unwrap();
        assert_same_geometry(&p, &back);
    }
}

#[test]
fn exported_files_verify() {
    for p in [
        samples::single_crease(3.0, 9),
        samples::degree4(PI / 3.0, 3.0, 13),
        samples::degree4(1.3, FRAC_PI_2, 4),
    ] {
        let f = FoldFile::parse(&fold_text(&p, FoldSpec::V1_2), "x.fold").unwrap();
        let r = verify(&f, &VerifyOptions::default());
        assert!(r.ok, "{r}");
        assert_eq!(r.frames.len(), p.frames.len());
        assert!(
            r.frames
                .iter()
                .all(|fr| fr.max_fold_angle_error_deg.is_some())
        );
    }
}

#[test]
fn nudged_vertex_fails_isometry_at_that_frame_only() {
    let mut p = samples::degree4(PI / 3.0, FRAC_PI_2, 5);
    p.frames[3].coords[6][2] += 1e-6;
    let f = FoldFile::parse(&fold_text(&p, FoldSpec::V1_2), "nudged.fold").unwrap();
    let r = verify(&f, &VerifyOptions::default());
    assert!(!r.ok);
    let bad: Vec<usize> = r
        .frames
        .iter()
        .filter(|fr| !fr.ok)
        .map(|fr| fr.frame)
        .collect();
    assert_eq!(bad, vec![4]); // frame 4 = file_frames[3]
    // Vertex 6 belongs to face 1 only.
    assert_eq!(r.frames[3].worst_face, Some(1));
    // With a looser tolerance the nudge passes.
    let loose = verify(
        &f,
        &VerifyOptions {
            tol: 1e-5,
            angle_tol_deg: 1e-3,
            ..VerifyOptions::default()
        },
    );
    assert!(loose.ok, "{loose}");
}

#[test]
fn fold_angles_from_geometry_match_the_construction() {
    // degree4 builds its angles from relative facet rotations; verify measures them from
    // face normals. The −x crease angle is only known through the rotations.
    let p = samples::degree4(1.1, 2.5, 6);
    let f = FoldFile::parse(&fold_text(&p, FoldSpec::V1_2), "d4.fold").unwrap();
    let adj = EdgeFaces::new(&f.edges, &f.faces);
    for fr in &p.frames {
        let geo = adj.fold_angles(&f.faces, &fr.coords);
        for (i, e) in p.edges.iter().enumerate() {
            match e.kind {
                EdgeKind::Boundary => assert!(geo[i].is_none()),
                _ => assert!(
                    (geo[i].unwrap() - fr.fold_angles[i]).abs() < 1e-12,
                    "edge {i} at t={}",
                    fr.t
                ),
            }
        }
        // Flat-foldable degree-4 vertex: the collinear creases fold by equal magnitude.
        assert!((fr.fold_angles[2].abs() - fr.t).abs() < 1e-12);
        // Maekawa: at t > 0 three creases of one kind, one of the other.
        if fr.t > 0.0 {
            let valleys = (0..4).filter(|&i| fr.fold_angles[i] > 0.0).count();
            assert!(valleys == 1 || valleys == 3);
        }
    }
}

#[test]
fn hand_written_spec_example_parses_and_verifies() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/diagonal_spec_example.fold"
    );
    let f = FoldFile::read(std::path::Path::new(path)).unwrap();
    assert_eq!(f.frames.len(), 4);
    assert_eq!(f.assignment[4], Assignment::V);
    assert!(f.frames[1].fold_angles_own);
    let r = verify(&f, &VerifyOptions::default());
    assert!(r.ok, "{r}");
    let p = f.to_pattern().unwrap();
    assert!((p.frames[0].fold_angles[4] - PI / 3.0).abs() < 1e-15);
    assert!((p.frames[1].fold_angles[4] - FRAC_PI_2).abs() < 1e-15);
    assert!(matches!(
        p.edges[4].kind,
        EdgeKind::Crease { driven: false }
    ));
}

#[test]
fn faces_are_derived_when_absent() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/mountain_no_faces.fold"
    );
    let f = FoldFile::read(std::path::Path::new(path)).unwrap();
    assert!(f.faces_derived);
    assert_eq!(f.faces.len(), 2);
    // Null fold angles (as Origami Simulator writes for boundary edges) are accepted.
    assert_eq!(f.frames[0].fold_angles.as_ref().unwrap()[0], None);
    let r = verify(&f, &VerifyOptions::default());
    assert!(r.ok, "{r}");
    // The mountain is −90° by geometry too.
    let p = f.to_pattern().unwrap();
    assert!((p.frames[0].fold_angles[6] + FRAC_PI_2).abs() < 1e-15);
}

#[test]
fn edges_are_derived_from_faces() {
    let text = r#"{"vertices_coords": [[0,0],[1,0],[1,1],[0,1]], "faces_vertices": [[0,1,2],[0,2,3]],
        "file_frames": [{"frame_inherit": true, "frame_parent": 0,
          "vertices_coords": [[0,0,0],[1,0,0],[1,1,0],[0,0,1e-20]]}]}"#;
    let f = FoldFile::parse(text, "t.fold").unwrap();
    assert!(f.edges_derived);
    assert_eq!(f.edges.len(), 5);
    assert_eq!(
        f.assignment.iter().filter(|a| **a == Assignment::B).count(),
        4
    );
    // Vertex 3 moved to (0,0,~0): face 1 is no longer isometric.
    let r = verify(&f, &VerifyOptions::default());
    assert!(!r.ok);
    assert_eq!(r.frames[0].worst_face, Some(1));
}

fn parse_err(text: &str) -> String {
    FoldFile::parse(text, "bad.fold").unwrap_err().to_string()
}

#[test]
fn malformed_files_name_the_field() {
    let ok_tail = r#""edges_vertices": [[0,1],[1,2],[2,0]], "faces_vertices": [[0,1,2]]"#;
    let cases: Vec<(String, &str, &str)> = vec![
        ("{".into(), "(file)", "not valid JSON"),
        ("[1, 2]".into(), "(file)", "JSON object"),
        (format!("{{{ok_tail}}}"), "vertices_coords", "missing"),
        (format!(r#"{{"vertices_coords": [[0,0],[1],[0,1]], {ok_tail}}}"#), "vertices_coords[1]", "1 coordinates"),
        (format!(r#"{{"vertices_coords": [[0,0],[1,0],["a",1]], {ok_tail}}}"#), "vertices_coords[2][0]", "expected a number"),
        (format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1e999]], {ok_tail}}}"#), "(file)", "too large to be finite"),
        (format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,NaN]], {ok_tail}}}"#), "(file)", "NaN"),
        (
            r#"{"vertices_coords": [[0,0],[1,0],[0,1]], "edges_vertices": [[0,1],[1,7],[2,0]], "faces_vertices": [[0,1,2]]}"#.into(),
            "edges_vertices[1][1]",
            "out of range",
        ),
        (
            r#"{"vertices_coords": [[0,0],[1,0],[0,1]], "faces_vertices": [[0,1,-2]]}"#.into(),
            "faces_vertices[0][2]",
            "non-negative integer",
        ),
        (
            r#"{"vertices_coords": [[0,0],[1,0],[0,1]], "faces_vertices": [[0,1]]}"#.into(),
            "faces_vertices[0]",
            "at least 3",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "edges_assignment": ["B","B","X"]}}"#),
            "edges_assignment[2]",
            "allowed are",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "edges_assignment": ["B","B","C"]}}"#),
            "edges_assignment[2]",
            "cut",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "edges_foldAngle": [0, 0]}}"#),
            "edges_foldAngle",
            "expected one per edge",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "edges_foldAngle": [0, 0, 200]}}"#),
            "edges_foldAngle[2]",
            "[-180, 180]",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "file_frames": [{{"frame_inherit": true, "frame_parent": 0, "vertices_coords": [[0,0,0],[1,0,0]]}}]}}"#),
            "file_frames[0].vertices_coords",
            "key frame has 3",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "file_frames": [{{"frame_inherit": true, "frame_parent": 5}}]}}"#),
            "file_frames[0].frame_parent",
            "out of range",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "file_frames": [{{"frame_inherit": "yes", "frame_parent": 0}}]}}"#),
            "file_frames[0].frame_inherit",
            "true or false",
        ),
        (
            format!(r#"{{"vertices_coords": [[0,0],[1,0],[0,1]], {ok_tail}, "file_frames": [3]}}"#),
            "file_frames[0]",
            "expected an object",
        ),
        (
            r#"{"vertices_coords": [[0,0],[1,0],[0,1]]}"#.into(),
            "faces_vertices",
            "edges_vertices",
        ),
        (
            r#"{"vertices_coords": [[0,0,0],[1,0,0],[0,1,1]], "edges_vertices": [[0,1],[1,2],[2,0]]}"#.into(),
            "faces_vertices",
            "not flat",
        ),
        (
            format!(r#"{{"vertices_coords": {{"a": 1}}, {ok_tail}}}"#),
            "vertices_coords",
            "expected an array",
        ),
    ];
    for (text, field, what) in cases {
        let e = parse_err(&text);
        assert!(e.starts_with("bad.fold: "), "{e}");
        assert!(
            e.contains(&format!(": {field}: ")) || field.is_empty(),
            "field {field:?} not named in: {e}"
        );
        assert!(e.contains(what), "expected {what:?} in: {e}");
    }
}

#[test]
fn frame_inheritance_is_resolved() {
    // Frame 2 inherits frame 1's coordinates (not the key frame's) and states its own
    // angles; frame 3 inherits without naming a parent (as Origami Simulator writes).
    let text = r#"{
      "vertices_coords": [[0,0],[1,0],[1,1],[0,1]],
      "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[3,1]],
      "edges_assignment": ["B","B","B","B","V"],
      "faces_vertices": [[0,1,3],[1,2,3]],
      "file_frames": [
        {"frame_parent": 0, "frame_inherit": true,
         "vertices_coords": [[0,0,0],[1,0,0],[0.5,0.5,0.7071067811865476],[0,1,0]]},
        {"frame_parent": 1, "frame_inherit": true, "edges_foldAngle": [0,0,0,0,90]},
        {"frame_inherit": true, "edges_foldAngle": [0,0,0,0,0]}
      ]}"#;
    let f = FoldFile::parse(text, "inherit.fold").unwrap();
    assert_eq!(f.frames[2].coords, f.frames[1].coords);
    assert!(f.frames[2].fold_angles_own && !f.frames[1].fold_angles_own);
    assert_eq!(f.frames[3].coords, f.frames[0].coords);
    let r = verify(&f, &VerifyOptions::default());
    assert!(r.ok, "{r}");
    // Frame 1 states no angles of its own: nothing to compare there.
    assert_eq!(r.frames[0].max_fold_angle_error_deg, None);
    assert!(r.frames[1].max_fold_angle_error_deg.unwrap() < 1e-12);

    let cyc = text.replace(
        r#""frame_parent": 0, "frame_inherit": true,"#,
        r#""frame_parent": 2, "frame_inherit": true,"#,
    );
    let e = FoldFile::parse(&cyc, "cycle.fold").unwrap_err().to_string();
    assert!(e.contains("cycle"), "{e}");
}

#[test]
fn faces_with_a_repeated_vertex_are_derived() {
    // A square with a dangling crease from the corner (0,0) to the centre: the derived
    // face walks the slit on both sides and visits vertex 0 twice.
    let text = r#"{"vertices_coords": [[0,0],[1,0],[1,1],[0,1],[0.5,0.5]],
      "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,4]],
      "edges_assignment": ["B","B","B","B","F"]}"#;
    let f = FoldFile::parse(text, "slit.fold").unwrap();
    assert_eq!(f.faces.len(), 1);
    let mut face = f.faces[0].clone();
    assert_eq!(face.len(), 6);
    assert_eq!(face.iter().filter(|&&v| v == 0).count(), 2);
    face.sort();
    assert_eq!(face, vec![0, 0, 1, 2, 3, 4]);
}
