//! `report.html`: every link resolves, and headless Chromium renders the page with no
//! console errors, no exceptions and every image loaded. The browser is driven over the
//! DevTools protocol on a pipe (`--remote-debugging-pipe`: NUL-terminated JSON on file
//! descriptors 3 and 4), so no extra crate is needed. Skips (printing why) when Chromium
//! is not installed.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use foldsynth::export::plots::{DistributionPlot, NodeStatus, Series, TreeNode};
use foldsynth::export::report::{
    CountRow, ReportDesign, ReportInput, ReportSummary, TimingRow, write_report,
};
use foldsynth::export::verify::{VerifyOptions, verify_file};
use foldsynth::export::{ExportOptions, samples, write_all};
use serde_json::{Value, json};

fn build_report(out: &Path) -> PathBuf {
    let mut designs = Vec::new();
    for (name, (p, m)) in [
        ("gripper_demo", samples::demo_gripper()),
        ("arm demo", samples::demo_arm()),
    ] {
        let opts = ExportOptions {
            name: name.into(),
            image_size: (240, 180),
            ..ExportOptions::default()
        };
        let files = write_all(&out.join("designs").join(name), &p, &m, &opts).unwrap();
        let verify = Some(verify_file(&files.fold, &VerifyOptions::default()).unwrap());
        designs.push(ReportDesign {
            title: format!("{} <{}>", m.task, m.rule_sequence),
            meta: m,
            files,
            verify,
            margins: vec![("rigid margin".into(), "0.1 rad".into())],
        });
    }
    let tree = vec![
        TreeNode {
            id: 0,
            parent: None,
            label: "2".into(),
            level: 1,
            status: NodeStatus::Meaningful,
        },
        TreeNode {
            id: 1,
            parent: Some(0),
            label: "2, 3".into(),
            level: 2,
            status: NodeStatus::Meaningful,
        },
        TreeNode {
            id: 2,
            parent: Some(0),
            label: "2, 4".into(),
            level: 2,
            status: NodeStatus::Invalid,
        },
        TreeNode {
            id: 3,
            parent: Some(0),
            label: "2, 5".into(),
            level: 2,
            status: NodeStatus::Mirror,
        },
        TreeNode {
            id: 4,
            parent: Some(1),
            label: "2, 3, (4, 8)".into(),
            level: 3,
            status: NodeStatus::Isomorphic,
        },
    ];
    let input = ReportInput {
        summary: ReportSummary {
            title: "foldsynth report & test".into(),
            task: "demo".into(),
            counts: vec![
                CountRow {
                    label: "alternatives".into(),
                    value: 2,
                    thesis: Some(1170),
                },
                CountRow {
                    label: "meet the target".into(),
                    value: 2,
                    thesis: Some(836),
                },
            ],
            timings: vec![TimingRow {
                stage: "export".into(),
                seconds: 0.25,
            }],
            notes: vec!["seed 1".into()],
        },
        tree,
        distribution: Some(DistributionPlot {
            title: "Designs over rule applications".into(),
            x_label: "rule applications".into(),
            y_label: "designs".into(),
            series: vec![
                Series {
                    name: "all".into(),
                    points: vec![[1.0, 1.0], [2.0, 3.0], [3.0, 1.0]],
                },
                Series {
                    name: "meets target".into(),
                    points: vec![[1.0, 1.0], [2.0, 2.0], [3.0, 0.0]],
                },
            ],
        }),
        designs,
    };
    write_report(out, &input).unwrap()
}

/// Every `src="…"` and `href="…"` of the page, decoded.
fn links(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for key in ["src=\"", "href=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(key) {
            rest = &rest[i + key.len()..];
            let end = rest.find('"').unwrap();
            out.push(rest[..end].to_string());
            rest = &rest[end..];
        }
    }
    out
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            out.push(u8::from_str_radix(&s[i + 1..i + 3], 16).unwrap());
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).unwrap()
}

#[test]
fn report_links_resolve_and_page_is_self_contained() {
    let dir = tempfile::tempdir().unwrap();
    let report = build_report(dir.path());
    let html = std::fs::read_to_string(&report).unwrap();
    let ls = links(&html);
    assert!(ls.len() >= 2 * (4 + 1 + 4 + 1 + 4), "{ls:?}");
    for l in &ls {
        assert!(
            !l.contains("://") && !l.starts_with('/'),
            "not a relative link: {l}"
        );
        assert!(dir.path().join(percent_decode(l)).is_file(), "missing: {l}");
    }
    // No scripts, no external resources.
    assert!(!html.contains("<script") && !html.contains("@import") && !html.contains("url("));
    // Two cards, each with an inline crease pattern; user text escaped.
    assert_eq!(html.matches("<article class=\"card\">").count(), 2);
    assert!(html.contains("demo gripper &lt;2&gt;"));
    assert!(html.contains("foldsynth report &amp; test"));
}

fn find_chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// What the browser reported about one page.
#[derive(Debug, Default)]
struct PageReport {
    errors: Vec<String>,
    warnings: Vec<String>,
    probe: Value,
}

struct Browser {
    child: std::process::Child,
    stdin: std::process::ChildStdin,
    rx: mpsc::Receiver<Value>,
    next_id: u64,
    events: Vec<Value>,
}

impl Browser {
    fn start(exe: &Path, profile: &Path) -> Browser {
        // fd 3 = commands (our stdin), fd 4 = replies (our stdout).
        let mut child = Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" 3<&0 4>&1 </dev/null >/dev/null 2>/dev/null")
            .arg(exe)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--remote-debugging-pipe",
            ])
            .arg(format!("--user-data-dir={}", profile.display()))
            .arg("about:blank")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("start chromium");
        let stdin = child.stdin.take().unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(stdout);
            loop {
                let mut buf = Vec::new();
                match r.read_until(0, &mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(_) => {
                        buf.pop();
                        if let Ok(v) = serde_json::from_slice::<Value>(&buf)
                            && tx.send(v).is_err()
                        {
                            break;
                        }
                    }
                }
            }
        });
        Browser {
            child,
            stdin,
            rx,
            next_id: 0,
            events: Vec::new(),
        }
    }

    fn send(&mut self, method: &str, params: Value, session: Option<&str>) -> u64 {
        self.next_id += 1;
        let mut msg = json!({"id": self.next_id, "method": method, "params": params});
        if let Some(s) = session {
            msg["sessionId"] = s.into();
        }
        let mut bytes = serde_json::to_vec(&msg).unwrap();
        bytes.push(0);
        self.stdin.write_all(&bytes).unwrap();
        self.stdin.flush().unwrap();
        self.next_id
    }

    fn wait(&mut self, until: impl Fn(&Value) -> bool, what: &str) -> Value {
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .rx
                .recv_timeout(left)
                .unwrap_or_else(|e| panic!("chromium: no {what} ({e})"));
            if let Some(err) = v.get("error") {
                panic!("chromium: {what} failed: {err}");
            }
            if until(&v) {
                return v;
            }
            if v.get("method").is_some() {
                self.events.push(v);
            }
        }
    }

    fn call(&mut self, method: &str, params: Value, session: Option<&str>) -> Value {
        let id = self.send(method, params, session);
        self.wait(|v| v["id"] == id, method)["result"].clone()
    }

    /// Load a page, wait for its load event, then collect console errors, exceptions,
    /// failed loads, and the result of a probe expression.
    fn load(&mut self, url: &str, probe: &str) -> PageReport {
        let target = self.call("Target.createTarget", json!({"url": "about:blank"}), None);
        let tid = target["targetId"].as_str().unwrap().to_string();
        let att = self.call(
            "Target.attachToTarget",
            json!({"targetId": tid, "flatten": true}),
            None,
        );
        let sid = att["sessionId"].as_str().unwrap().to_string();
        for m in ["Runtime.enable", "Log.enable", "Page.enable"] {
            self.call(m, json!({}), Some(&sid));
        }
        self.events.clear();
        self.call("Page.navigate", json!({"url": url}), Some(&sid));
        let s2 = sid.clone();
        self.wait(
            move |v| v["method"] == "Page.loadEventFired" && v["sessionId"] == s2.as_str(),
            "load event",
        );
        let probe = self.call(
            "Runtime.evaluate",
            json!({"expression": probe, "returnByValue": true}),
            Some(&sid),
        )["result"]["value"]
            .clone();
        let mut r = PageReport {
            probe,
            ..PageReport::default()
        };
        for e in &self.events {
            let p = &e["params"];
            match e["method"].as_str() {
                Some("Runtime.exceptionThrown") => r
                    .errors
                    .push(format!("exception: {}", p["exceptionDetails"])),
                Some("Runtime.consoleAPICalled") => {
                    let msg = format!("console.{}: {}", p["type"], p["args"]);
                    match p["type"].as_str() {
                        Some("error" | "assert") => r.errors.push(msg),
                        Some("warning") => r.warnings.push(msg),
                        _ => {}
                    }
                }
                Some("Log.entryAdded") => {
                    let msg = format!(
                        "{}: {} {}",
                        p["entry"]["source"], p["entry"]["text"], p["entry"]["url"]
                    );
                    match p["entry"]["level"].as_str() {
                        Some("error") => r.errors.push(msg),
                        Some("warning") => r.warnings.push(msg),
                        _ => {}
                    }
                }
                _ => {}
            }
        }
        r
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.send("Browser.close", json!({}), None);
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

const PROBE: &str = "JSON.stringify({images: Array.from(document.images).map(i => [i.getAttribute('src'), i.complete && i.naturalWidth > 0]), svgs: document.querySelectorAll('svg').length, cards: document.querySelectorAll('article.card').length, height: document.body.scrollHeight})";

fn file_url(p: &Path) -> String {
    let abs = p.canonicalize().unwrap();
    format!("file://{}", abs.display()).replace(' ', "%20")
}

#[test]
fn report_renders_in_headless_chromium_without_errors() {
    let Some(exe) = find_chromium() else {
        println!(
            "SKIPPED: chromium not found in PATH (install Debian's `chromium` to run this check)"
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let report = build_report(&dir.path().join("out"));

    // A deliberately broken page first: the harness must see its errors.
    let broken = dir.path().join("broken.html");
    std::fs::write(
        &broken,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>b</title></head><body><img src=\"nope.png\"><script>console.error('boom'); undefined_fn();</script></body></html>",
    )
    .unwrap();

    let mut browser = Browser::start(&exe, &dir.path().join("profile"));
    let bad = browser.load(&file_url(&broken), PROBE);
    assert!(bad.errors.iter().any(|e| e.contains("boom")), "{bad:?}");
    assert!(
        bad.errors.iter().any(|e| e.contains("exception")),
        "{bad:?}"
    );
    let probe: Value = serde_json::from_str(bad.probe.as_str().unwrap()).unwrap();
    assert_eq!(probe["images"][0][1], false, "{probe}");

    let good = browser.load(&file_url(&report), PROBE);
    assert!(good.errors.is_empty(), "console errors: {:#?}", good.errors);
    for w in &good.warnings {
        println!("warning: {w}");
    }
    let probe: Value = serde_json::from_str(good.probe.as_str().unwrap()).unwrap();
    let images = probe["images"].as_array().unwrap();
    // Per design: 4 state pictures and the animation.
    assert_eq!(images.len(), 2 * 5, "{probe}");
    for img in images {
        assert_eq!(img[1], true, "image did not load: {img}");
    }
    assert_eq!(probe["cards"], 2);
    // Tree, distribution, and per card the crease pattern.
    assert!(probe["svgs"].as_u64().unwrap() >= 4, "{probe}");
    assert!(probe["height"].as_u64().unwrap() > 500, "{probe}");
}
