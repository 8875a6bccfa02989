//! No lost files (issue 8, SPEC §4): a render interrupted mid-way by SIGTERM or SIGINT (Ctrl-C)
//! exits non-zero (128 + the signal: 130, 143), leaves no temporary (`.formation-PID-RANDOM.tmp`, `.tmpdir`), never touches an
//! existing output (byte-identical afterwards) and creates no later output.
//!
//! The render is made slow on purpose (a 70-second animation as a 1280×720 GIF at 50 fps, or as
//! PNG frames); the signal is sent once the output's temporary exists, i.e. while it is being
//! written. Signals are sent with the `kill` command (no `libc` dependency).
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use formation::Animation;

mod support;

use support::{bin, data, scratch};

const PREVIOUS: &[u8] = b"previous output: an interrupted run must leave this byte-identical\n";

/// A render slow enough to be interrupted, up to its `-o`.
const SLOW_RENDER: [&str; 7] = [
    "render",
    "--quiet",
    "--size",
    "1280x720",
    "--picture-fps",
    "50",
    "-o",
];

/// A long animation: `tests/data/flock_small.json` (50 frames, 1.6 s) slowed down 40 times.
fn long_animation(dir: &Path) -> PathBuf {
    let src = data("flock_small.json");
    let mut a = Animation::read(&src).unwrap();
    for f in &mut a.frames {
        f.t *= 40.0;
    }
    a.fps /= 40.0;
    let path = dir.join("long.json");
    std::fs::write(&path, serde_json::to_vec(&a).unwrap()).unwrap();
    path
}

/// Every file under `dir` (relative path → bytes), sorted.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                out.push((
                    p.strip_prefix(dir).unwrap().display().to_string() + "/",
                    Vec::new(),
                ));
                stack.push(p);
            } else {
                let bytes = std::fs::read(&p).unwrap_or_default();
                out.push((p.strip_prefix(dir).unwrap().display().to_string(), bytes));
            }
        }
    }
    out.sort();
    out
}

fn has_temporary(dir: &Path) -> bool {
    !temporaries(dir).is_empty()
}

/// Names of the temporaries under `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    snapshot(dir)
        .into_iter()
        .map(|(name, _)| name)
        .filter(|name| name.contains(".formation-"))
        .collect()
}

/// Waits until `child` is writing its output: a temporary that is still there 200 ms after it
/// was first seen. A run first creates and removes a probe temporary or two (to check that the
/// output's directory is writable before any work); a SIGKILL that landed between a probe's
/// removal and the real temporary left none, and failed the test once in a full suite run.
fn wait_for_lasting_temporary(dir: &Path, child: &mut std::process::Child) {
    let start = Instant::now();
    loop {
        assert!(child.try_wait().unwrap().is_none(), "render ended early");
        assert!(start.elapsed() < Duration::from_secs(120));
        let seen = temporaries(dir);
        if !seen.is_empty() {
            std::thread::sleep(Duration::from_millis(200));
            if temporaries(dir).iter().any(|n| seen.contains(n)) {
                return;
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Starts `formation render` writing `output` (then `later`), waits until it is writing, sends
/// `signal`, and checks the aftermath.
fn interrupt(signal: &str, name: &str, output: &str) {
    // 128 + the signal's number, as shells report a run ended by a signal.
    let code = if signal == "INT" { 130 } else { 143 };
    interrupt_with(signal, name, output, code, "interrupted; no output written");
}

/// [`interrupt`] for any catchable signal, with its expected exit code and message.
fn interrupt_with(signal: &str, name: &str, output: &str, code: i32, message: &str) {
    let dir = scratch(name);
    let anim = long_animation(&dir);
    // Existing outputs that must survive: the file itself, or a frames directory of ours.
    if output.ends_with('/') {
        let frames = dir.join(output.trim_end_matches('/'));
        std::fs::create_dir(&frames).unwrap();
        std::fs::write(frames.join("frame_00000.png"), PREVIOUS).unwrap();
    } else {
        std::fs::write(dir.join(output), PREVIOUS).unwrap();
    }
    let before = snapshot(&dir);
    let mut child = bin()
        .args(SLOW_RENDER)
        .arg(dir.join(output))
        .arg("-o")
        .arg(dir.join("later.csv"))
        .arg(&anim)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !has_temporary(&dir) {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("{name}: render ended ({status}) before writing anything");
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "{name}: no temporary after 2 minutes"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    // Let it write for a while: the temporary holds part of the output.
    std::thread::sleep(Duration::from_millis(300));
    assert!(
        child.try_wait().unwrap().is_none(),
        "{name}: render finished before the signal; make it slower"
    );
    let killed = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(code),
        "{name}: exit {:?}, stderr {stderr}",
        out.status
    );
    assert!(stderr.contains(message), "{name}: {stderr}");
    let after = snapshot(&dir);
    assert_eq!(
        after.iter().map(|e| &e.0).collect::<Vec<_>>(),
        before.iter().map(|e| &e.0).collect::<Vec<_>>(),
        "{name}: files differ after the interruption (temporaries or new outputs left)"
    );
    assert!(after == before, "{name}: an existing output changed");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn sigterm_during_gif_keeps_the_old_gif() {
    interrupt("TERM", "term-gif", "flock.gif");
}

#[test]
fn sigint_during_gif_keeps_the_old_gif() {
    interrupt("INT", "int-gif", "flock.gif");
}

#[test]
fn sigterm_during_png_frames_keeps_the_old_frames() {
    interrupt("TERM", "term-png", "frames/");
}

#[test]
fn sigint_during_png_frames_keeps_the_old_frames() {
    interrupt("INT", "int-png", "frames/");
}

/// Signals the tool does not treat as Ctrl-C still end the run cleanly (issue 17: SIGUSR1,
/// SIGALRM, SIGXCPU and SIGHUP used to leave the temporary forever): exit 128 + the signal.
#[test]
fn other_catchable_signals_clean_up_too() {
    for (signal, code) in [("HUP", 129), ("USR1", 138), ("ALRM", 142), ("XCPU", 152)] {
        interrupt_with(
            signal,
            &format!("{}-gif", signal.to_lowercase()),
            "flock.gif",
            code,
            &format!("stopped by signal SIG{signal}; no output written"),
        );
    }
}

/// SIGKILL cannot be caught: its temporary stays, and the next run writing into the same
/// directory recognises it as a dead run's and removes it.
#[test]
fn a_killed_runs_temporary_is_removed_by_the_next_run() {
    let dir = scratch("kill");
    let anim = long_animation(&dir);
    let mut child = bin()
        .args(SLOW_RENDER)
        .arg(dir.join("flock.gif"))
        .arg(&anim)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    wait_for_lasting_temporary(&dir, &mut child);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(has_temporary(&dir), "SIGKILL should leave the temporary");
    let small = data("flock_small.json");
    let ok = bin()
        .args(["render", "--quiet", "-o"])
        .arg(dir.join("small.csv"))
        .arg(&small)
        .status()
        .unwrap();
    assert!(ok.success());
    assert!(
        !has_temporary(&dir),
        "{:?}",
        snapshot(&dir).iter().map(|e| &e.0).collect::<Vec<_>>()
    );
    assert!(dir.join("small.csv").is_file());
    assert!(!dir.join("flock.gif").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A write that fails (a number JSON cannot hold) refuses before creating anything: the existing
/// file stays byte-identical and no temporary is left.
#[test]
fn failed_write_leaves_no_temporary_and_keeps_the_target() {
    let dir = scratch("failed");
    let target = dir.join("out.json");
    std::fs::write(&target, PREVIOUS).unwrap();
    #[derive(serde::Serialize)]
    struct Bad {
        x: Vec<f64>,
    }
    let e = formation::io::write_json_atomic(
        &target,
        &Bad {
            x: vec![1.0, f64::NAN],
        },
    )
    .unwrap_err();
    assert_eq!(e.exit_code(), 1);
    assert!(e.to_string().contains("x[1]"), "{e}");
    assert_eq!(std::fs::read(&target).unwrap(), PREVIOUS);
    assert_eq!(snapshot(&dir).len(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}
