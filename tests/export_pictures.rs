//! PNG and GIF output decode to the requested size, and the animation shows the motion.

use foldsynth::export::render::{Camera, Scene};
use foldsynth::export::{DesignMeta, picked_frames, samples};

#[test]
fn picked_frames_are_even_and_keep_the_ends() {
    assert_eq!(picked_frames(9, 4), vec![0, 3, 5, 8]);
    assert_eq!(picked_frames(3, 10), vec![0, 1, 2]);
    assert_eq!(picked_frames(5, 1), vec![4]);
    assert!(picked_frames(0, 3).is_empty());
    let p = picked_frames(1000, 60);
    assert_eq!((p.len(), p[0], p[59]), (60, 0, 999));
    assert!(p.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn png_decodes_to_the_requested_size() {
    let p = samples::degree4(1.2, 1.5, 3);
    let meta = DesignMeta::default();
    let scene = Scene::new(&p, &meta, Camera::default()).unwrap();
    let png = scene.png(Some(2), (321, 123)).unwrap();
    let img = tiny_skia::Pixmap::decode_png(&png).unwrap();
    assert_eq!((img.width(), img.height()), (321, 123));
    assert!(
        scene
            .png(Some(2), (8, 8))
            .unwrap_err()
            .to_string()
            .contains("16..=4096")
    );
}

#[test]
fn gif_has_the_picked_frames_and_they_move() {
    let p = samples::single_crease(3.0, 100);
    let meta = DesignMeta {
        scene: foldsynth::scene::Scene {
            copies: foldsynth::scene::Copies::about_z(2),
            ..Default::default()
        },
        ..DesignMeta::default()
    };
    let scene = Scene::new(&p, &meta, Camera::default()).unwrap();
    let bytes = scene.gif((120, 90), 4, 12).unwrap();
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts.read_info(bytes.as_slice()).unwrap();
    assert_eq!((dec.width(), dec.height()), (120, 90));
    // Frames after the first hold only what changed (transparent elsewhere): compose them
    // over the canvas as a viewer does.
    let mut canvas = vec![0u8; 120 * 90];
    let mut frames = Vec::new();
    while let Some(f) = dec.read_next_frame().unwrap() {
        let fw = usize::from(f.width);
        for (i, &px) in f.buffer.iter().enumerate() {
            if Some(px) != f.transparent {
                canvas[(usize::from(f.top) + i / fw) * 120 + usize::from(f.left) + i % fw] = px;
            }
        }
        frames.push((f.delay, canvas.clone()));
    }
    assert_eq!(frames.len(), 12);
    // The sheet moves: first and last pictures differ; the last frame lingers.
    assert_ne!(frames[0].1, frames[11].1);
    assert_eq!(frames[0].0, 4);
    assert!(frames[11].0 > 4);
}

/// `foldsynth bench export` measures every part of one design's files and the two LZW
/// encoders on the same data; a missing file is an error that names it.
#[test]
fn bench_export_reports_every_part() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let design = dir.path().join("design.json");
    let d = foldsynth::export::DesignFile {
        pattern: samples::single_crease(2.0, 20),
        meta: DesignMeta {
            task: "bench".into(),
            ..DesignMeta::default()
        },
    };
    std::fs::write(&design, serde_json::to_string(&d).unwrap()).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(["bench", "export"])
        .arg(&design)
        .args(["--millis", "1", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let parts: Vec<&str> = v["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            assert!(r["ns"].as_f64().unwrap() > 0.0, "{r}");
            r["part"].as_str().unwrap()
        })
        .collect();
    for want in [
        "FOLD file",
        "crease-pattern SVG",
        "OBJ and STL of the last state",
        "PNG pictures: draw, anti-aliased",
        "PNG pictures: encode",
        "SVG pictures of the same states",
        "GIF frames: draw into palette entries",
        "GIF frames: delta rectangles",
        "GIF frames: LZW (export::lzw)",
    ] {
        assert!(parts.contains(&want), "{want} missing from {parts:?}");
    }
    // 20 frames, all in the GIF; the default 4 pictures.
    assert_eq!(v["gif_frames"], 20, "{v}");
    assert_eq!(v["pictures"], 4, "{v}");
    let lzw = &v["lzw"];
    // 20 frames of 480×360 at most, the first whole.
    let input = lzw["input_bytes"].as_u64().unwrap();
    assert!((480 * 360..=20 * 480 * 360).contains(&input), "{lzw}");
    assert!(lzw["ours_bytes"].as_u64().unwrap() > 0, "{lzw}");
    assert!(lzw["gif_crate_bytes"].as_u64().unwrap() > 0, "{lzw}");
    assert!(v["write_all_ns"].as_f64().unwrap() > 0.0, "{v}");

    let o = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(["bench", "export", "no-such-design.json"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("no-such-design.json"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
