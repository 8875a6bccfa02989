//! Hardening, second round (issue 17): no file lost through a link, no panic on a closed pipe,
//! bounded work. One regression test per finding of the probe, each checking what the user
//! cares about: the victim file of a planted link untouched, outputs committed together or not at
//! all, exit codes and the one-line message, memory bounded (each run under `ulimit -v`), work
//! bounded in CPU time (not wall-clock time, which a loaded machine stretches).
#![cfg(unix)]

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

const VICTIM: &[u8] = b"a file the user cares about: no run of formation may change it\n";

mod support;

use support::{
    assert_refused, assert_usage_error_in, bin, repo_file, run_capped, run_in, scratch, stderr,
};

/// Names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The last PID the kernel handed out, to predict the next ones (Linux).
fn last_pid() -> u32 {
    std::fs::read_to_string("/proc/sys/kernel/ns_last_pid")
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(std::process::id())
}

/// Every command that writes a file, with the outputs it writes (relative to its directory).
fn writing_commands() -> Vec<(&'static str, Vec<String>, Vec<&'static str>)> {
    let ex = repo_file("examples_data/barnacle_geese_v.json")
        .display()
        .to_string();
    let params = repo_file("tests/data/steady_v9_params.json")
        .display()
        .to_string();
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    let shape = repo_file("examples_data/v9_shape.json")
        .display()
        .to_string();
    let target = repo_file("examples_data/equal_savings_target.json")
        .display()
        .to_string();
    vec![
        (
            "extract",
            vec!["extract".into(), ex.clone(), "-o".into(), "p.json".into()],
            vec!["p.json"],
        ),
        (
            "steady",
            vec![
                "steady".into(),
                params,
                "--birds".into(),
                "9".into(),
                "--frames".into(),
                "30".into(),
                "-o".into(),
                "s.json".into(),
                "--report".into(),
                "r.json".into(),
            ],
            vec!["s.json", "r.json"],
        ),
        (
            "render",
            vec![
                "render".into(),
                anim.clone(),
                "-o".into(),
                "a.gif".into(),
                "-o".into(),
                "a.glb".into(),
                "-o".into(),
                "a.csv".into(),
                "-o".into(),
                "fr/".into(),
            ],
            vec!["a.gif", "a.glb", "a.csv", "fr"],
        ),
        (
            "animate",
            vec![
                "animate".into(),
                ex,
                "--birds".into(),
                "5".into(),
                "--seconds".into(),
                "1".into(),
                "--no-initiation".into(),
                "-o".into(),
                "m.json".into(),
            ],
            vec!["m.json"],
        ),
        (
            "solve",
            vec!["solve".into(), target, "-o".into(), "sol.json".into()],
            vec!["sol.json"],
        ),
        (
            "plot",
            vec![
                "plot".into(),
                "xi".into(),
                anim,
                "-o".into(),
                "c.png".into(),
            ],
            vec!["c.png"],
        ),
        (
            "plot shape",
            vec![
                "plot".into(),
                "power".into(),
                shape,
                "-o".into(),
                "d.svg".into(),
            ],
            vec!["d.svg"],
        ),
    ]
}

/// Symbolic links planted where the old code put its temporaries (`.NAME.tmp-formation-PID`,
/// for the next few thousand PIDs) and at the outputs themselves point at a victim file: no
/// command may write through them. The outputs end up as regular files of their own.
#[test]
fn planted_links_are_never_followed() {
    for (name, args, outputs) in writing_commands() {
        let dir = scratch(&format!("links-{}", name.replace(' ', "-")));
        let victim = dir.join("victim.txt");
        std::fs::write(&victim, VICTIM).unwrap();
        let next = last_pid();
        for out in &outputs {
            for pid in next + 1..next + 1500 {
                let link = dir.join(format!(".{out}.tmp-formation-{pid}"));
                std::os::unix::fs::symlink(&victim, link).unwrap();
            }
        }
        // The first output itself is a link to the victim (replaced, not written through).
        std::os::unix::fs::symlink(&victim, dir.join(outputs[0])).unwrap();
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run_in(&dir, &argv);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert_eq!(
            std::fs::read(&victim).unwrap(),
            VICTIM,
            "{name}: victim changed"
        );
        for out in &outputs {
            let meta = std::fs::symlink_metadata(dir.join(out)).unwrap();
            assert!(
                !meta.file_type().is_symlink(),
                "{name}: {out} is still a link"
            );
            assert!(meta.is_dir() || meta.len() > 0, "{name}: {out} is empty");
        }
        assert!(
            !names(&dir).iter().any(|n| n.starts_with(".formation-")),
            "{name}: temporary left"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// The outputs of one run are committed together or not at all: when the GIF (the second
/// output) crosses a file-size limit, the CSV written before it is not kept and the earlier
/// CSV stays byte-identical. The limit's SIGXFSZ does not kill the run: it ends with exit 2
/// naming the output.
#[test]
fn a_failed_multi_output_run_keeps_none_of_its_outputs() {
    let dir = scratch("atomic-set");
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    std::fs::write(dir.join("a.csv"), VICTIM).unwrap();
    // 200 blocks: more than the CSV needs, far less than the GIF.
    let (o, _) = run_capped(
        &dir,
        4_000_000,
        Some(200),
        &[
            "render", &anim, "-o", "a.csv", "-o", "a.gif", "-o", "a.json",
        ],
    );
    assert_refused(&o, "a.gif: File too large", "render under ulimit -f");
    assert_eq!(std::fs::read(dir.join("a.csv")).unwrap(), VICTIM);
    assert_eq!(names(&dir), vec!["a.csv"]);
    // Without the limit all three are written.
    let o = run_in(
        &dir,
        &[
            "render", &anim, "-o", "a.csv", "-o", "a.gif", "-o", "a.json",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(&dir), vec!["a.csv", "a.gif", "a.json"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--report` is an output like `-o`: the same file for both is refused up front, and a report
/// in a missing directory fails before any output is written.
#[test]
fn report_outputs_are_checked_with_the_others() {
    let dir = scratch("report");
    let params = repo_file("tests/data/steady_v9_params.json")
        .display()
        .to_string();
    let base = [
        "steady", &params, "--birds", "9", "--frames", "30", "-o", "a.json",
    ];
    for (report, needle) in [
        ("a.json", "--report: a.json: is also an output"),
        ("./a.json", "--report: ./a.json: is also an output"),
        (
            "nodir/r.json",
            "--report: nodir/r.json: directory nodir does not exist",
        ),
        ("r.txt", "--report: r.txt: cannot tell the output format"),
    ] {
        let mut args = base.to_vec();
        args.extend(["--report", report]);
        let o = run_in(&dir, &args);
        assert_refused(&o, needle, report);
        assert!(names(&dir).is_empty(), "{report}: {:?}", names(&dir));
    }
    // `-o a.json -o ./a.json` is one file given twice.
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    let o = run_in(&dir, &["render", &anim, "-o", "a.json", "-o", "./a.json"]);
    assert_refused(&o, "given twice", "-o twice");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The commands that print tables or `--json` on stdout.
fn printing_commands() -> Vec<(&'static str, Vec<String>)> {
    let ex = repo_file("examples_data/barnacle_geese_v.json")
        .display()
        .to_string();
    let shape = repo_file("examples_data/v9_shape.json")
        .display()
        .to_string();
    let steady = repo_file("tests/data/initiate_steady_v9.json")
        .display()
        .to_string();
    vec![
        (
            "extract table",
            vec!["extract".into(), ex.clone(), "-o".into(), "p.json".into()],
        ),
        (
            "extract --json",
            vec!["extract".into(), ex, "--json".into()],
        ),
        ("power table", vec!["power".into(), shape.clone()]),
        ("power --json", vec!["power".into(), shape, "--json".into()]),
        (
            "initiate --json",
            vec![
                "initiate".into(),
                steady,
                "-o".into(),
                "i.json".into(),
                "--json".into(),
            ],
        ),
    ]
}

/// A reader that goes away (`| head -1`) ends the printing quietly: exit 0, nothing on stderr,
/// and the command's output files are still written.
#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    for (name, args) in printing_commands() {
        let dir = scratch(&format!("pipe-{}", name.replace([' ', '-'], "")));
        let mut child = bin()
            .current_dir(&dir)
            .arg("--quiet")
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{name}: {}", stderr(&o));
        assert_eq!(stderr(&o), "", "{name}");
        if let Some(k) = args.iter().position(|a| a == "-o") {
            assert!(
                dir.join(&args[k + 1]).is_file(),
                "{name}: output not written"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// A full device on stdout is bad output, exit 2 naming stdout, and no output file is kept.
#[test]
fn a_full_stdout_is_exit_2_naming_stdout() {
    if !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    for (name, args) in printing_commands() {
        let dir = scratch(&format!("full-{}", name.replace([' ', '-'], "")));
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let mut cmd = bin();
        cmd.current_dir(&dir);
        // `extract`'s table is its summary, which `--quiet` silences: it prints only without.
        if name != "extract table" {
            cmd.arg("--quiet");
        }
        let o = cmd.args(&args).stdout(full).output().unwrap();
        assert_refused(&o, "stdout: No space left on device", name);
        assert!(names(&dir).is_empty(), "{name}: {:?}", names(&dir));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// Legal names up to 255 bytes work: the temporary's name no longer grows with the target's.
#[test]
fn the_longest_legal_output_names_work() {
    let dir = scratch("long-names");
    let ex = repo_file("examples_data/barnacle_geese_v.json")
        .display()
        .to_string();
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    let json = format!("{}.json", "p".repeat(250));
    let gif = format!("{}.gif", "g".repeat(251));
    let frames = format!("{}/", "f".repeat(255));
    let o = run_in(&dir, &["extract", &ex, "-o", &json]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run_in(&dir, &["render", &anim, "-o", &gif, "-o", &frames]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join(&json).is_file() && dir.join(&gif).is_file());
    assert!(dir.join(frames.trim_end_matches('/')).is_dir());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PID that no process has (a child that has exited and been reaped).
fn dead_pid() -> u32 {
    let mut c = Command::new("true").spawn().unwrap();
    let pid = c.id();
    c.wait().unwrap();
    assert!(!Path::new(&format!("/proc/{pid}")).exists());
    pid
}

/// Temporaries of dead runs (SIGKILL, a crash) are removed by the next run writing into the same
/// directory, safely: only our exact naming, only dead processes', never a link (nor what it
/// points to), never a live run's.
#[test]
fn stale_temporaries_are_removed_safely() {
    if !Path::new("/proc/self").exists() {
        eprintln!("skipped: no /proc");
        return;
    }
    let dir = scratch("stale");
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, VICTIM).unwrap();
    let dead = dead_pid();
    let live = std::process::id();
    let stale_file = format!(".formation-{dead}-AAAAAAAAAAAA.tmp");
    let stale_dir = format!(".formation-{dead}-BBBBBBBBBBBB.tmpdir");
    let stale_link = format!(".formation-{dead}-CCCCCCCCCCCC.tmp");
    let live_file = format!(".formation-{live}-DDDDDDDDDDDD.tmp");
    let not_ours = format!(".formation-{dead}-short.tmp");
    std::fs::write(dir.join(&stale_file), b"partial").unwrap();
    std::fs::create_dir(dir.join(&stale_dir)).unwrap();
    std::fs::write(dir.join(&stale_dir).join("frame_00000.png"), b"partial").unwrap();
    std::os::unix::fs::symlink(&victim, dir.join(&stale_link)).unwrap();
    std::fs::write(dir.join(&live_file), b"in use").unwrap();
    std::fs::write(dir.join(&not_ours), b"someone else's").unwrap();
    let ex = repo_file("examples_data/barnacle_geese_v.json")
        .display()
        .to_string();
    let o = run_in(&dir, &["extract", &ex, "-o", "p.json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let left = names(&dir);
    assert!(
        !left.contains(&stale_file) && !left.contains(&stale_dir),
        "{left:?}"
    );
    for kept in [&stale_link, &live_file, &not_ours] {
        assert!(left.contains(kept), "{kept} removed: {left:?}");
    }
    assert_eq!(std::fs::read(&victim).unwrap(), VICTIM);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Endless or binary inputs are refused at once, in bounded memory: `/dev/zero`, `/dev/urandom`,
/// an endless text stream through a FIFO. A FIFO holding a real file works (process substitution).
#[test]
fn endless_and_binary_inputs_are_refused_at_once() {
    let dir = scratch("endless");
    for dev in ["/dev/zero", "/dev/urandom"] {
        for args in [
            vec!["extract", dev, "-o", "p.json"],
            vec!["render", dev, "-o", "a.gif"],
            vec!["power", dev],
        ] {
            let (o, cpu) = run_capped(&dir, 400_000, None, &args);
            assert_refused(&o, &format!("{dev}: binary data"), &args.join(" "));
            assert!(
                cpu < Duration::from_secs(20),
                "{args:?} used {cpu:?} of CPU"
            );
        }
    }
    // A FIFO fed with the example works like the file.
    let fifo = dir.join("in.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let ex = std::fs::read(repo_file("examples_data/barnacle_geese_v.json")).unwrap();
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            std::fs::OpenOptions::new()
                .write(true)
                .open(fifo)
                .unwrap()
                .write_all(&ex)
                .unwrap();
        })
    };
    let o = run_in(&dir, &["extract", "in.fifo", "-o", "p.json"]);
    writer.join().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // An endless stream of blanks is cut at the stream limit, in bounded memory.
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut f = std::fs::OpenOptions::new().write(true).open(fifo).unwrap();
            let chunk = vec![b' '; 1 << 16];
            while f.write_all(&chunk).is_ok() {}
        })
    };
    let (o, cpu) = run_capped(
        &dir,
        1_000_000,
        None,
        &["extract", "in.fifo", "-o", "q.json"],
    );
    writer.join().unwrap();
    assert_refused(&o, "from a pipe or device", "endless FIFO");
    assert!(
        cpu < Duration::from_secs(60),
        "endless FIFO used {cpu:?} of CPU"
    );
    assert!(!dir.join("q.json").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Writes a shape of `n` birds in a wide V (one bird a wingspan further out and back each).
fn big_shape(path: &Path, n: usize) {
    let birds: Vec<String> = (0..n)
        .map(|i| format!("{{\"x\": {}, \"y\": {}}}", i as f64, i as f64 * 0.5))
        .collect();
    std::fs::write(path, format!("{{\"birds\": [{}]}}", birds.join(","))).unwrap();
}

/// Requests beyond the limits are refused within seconds and bounded memory: `power` and `solve`
/// with too many birds, an animation file with 10⁶ birds, values beyond f32 in an animation file.
#[test]
fn size_limits_are_refused_early() {
    let dir = scratch("limits");
    big_shape(&dir.join("big.json"), 100_000);
    let (o, cpu) = run_capped(&dir, 1_000_000, None, &["power", "big.json"]);
    assert_refused(
        &o,
        "big.json: birds: 100000 birds given, at most 10000",
        "power",
    );
    assert!(cpu < Duration::from_secs(10), "power used {cpu:?} of CPU");

    let xs: Vec<String> = (0..40_000).map(|i| format!("{}", i as f64)).collect();
    let xi: Vec<&str> = vec!["1"; 40_000];
    std::fs::write(
        dir.join("target.json"),
        format!("{{\"x\": [{}], \"xi\": [{}]}}", xs.join(","), xi.join(",")),
    )
    .unwrap();
    let (o, cpu) = run_capped(
        &dir,
        1_000_000,
        None,
        &["solve", "target.json", "-o", "s.json"],
    );
    assert_refused(&o, "target.json: x: 40000 birds: at most 10000", "solve");
    assert!(cpu < Duration::from_secs(10), "solve used {cpu:?} of CPU");

    // One frame of 10⁶ birds (about 18 MB of JSON).
    let n = 1_000_000;
    let zeros = vec!["0"; n].join(",");
    let anim = format!(
        "{{\"format\": \"formation-animation/1\", \"seed\": 0, \"fps\": 30, \"wingspan_m\": 1.5, \
         \"birds\": {n}, \"stages\": [], \"frames\": [{{\"t\": 0, \"x\": [{zeros}], \"y\": [{zeros}], \
         \"z\": [{zeros}], \"heading\": [{zeros}], \"speed\": [{zeros}]}}]}}"
    );
    std::fs::write(dir.join("million.json"), anim).unwrap();
    let (o, cpu) = run_capped(
        &dir,
        2_000_000,
        None,
        &["render", "million.json", "-o", "m.glb"],
    );
    assert_refused(
        &o,
        "million.json: 1000000 birds: at most 100000",
        "render 10⁶ birds",
    );
    assert!(cpu < Duration::from_secs(20), "render used {cpu:?} of CPU");

    // Native annotations with one frame of 10⁶ birds (18 MB): counted before they are parsed,
    // refused in the memory of the text (the parsed tree would take about 1.2 GB).
    let pts = vec!["[1,2]"; n].join(",");
    std::fs::write(
        dir.join("crowd.json"),
        format!("{{\"wingspan_px\": 30, \"frames\": [{{\"index\": 0, \"birds\": [{pts}]}}]}}"),
    )
    .unwrap();
    let (o, cpu) = run_capped(
        &dir,
        300_000,
        None,
        &["extract", "crowd.json", "-o", "p.json"],
    );
    assert_refused(
        &o,
        "crowd.json: frames[0]: more than 1000 birds marked",
        "crowd",
    );
    assert!(cpu < Duration::from_secs(10), "crowd used {cpu:?} of CPU");

    // Values beyond f32 range in an animation file name the frame and field.
    let small = std::fs::read_to_string(repo_file("tests/data/flock_small.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&small).unwrap();
    for (field, value, needle) in [
        ("heading", 1e300, "frames[3].heading[1]: 1e300 is beyond"),
        ("x", 1e200, "frames[3].x[1]: 1e200 is beyond"),
    ] {
        let mut w = v.clone();
        w["frames"][3][field][1] = serde_json::json!(value);
        std::fs::write(dir.join("huge.json"), serde_json::to_vec(&w).unwrap()).unwrap();
        let o = run_in(&dir, &["render", "huge.json", "-o", "h.glb"]);
        assert_refused(&o, needle, field);
    }
    v["wingspan_m"] = serde_json::json!(1e300);
    std::fs::write(dir.join("huge.json"), serde_json::to_vec(&v).unwrap()).unwrap();
    let o = run_in(&dir, &["render", "huge.json", "-o", "h.glb"]);
    assert_refused(
        &o,
        "wingspan_m: must be a number of metres from 0.01 to 1000",
        "wingspan",
    );
    assert!(!dir.join("h.glb").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The long-CSV reader is linear in frames: 100 001 one-bird frames are read and refused by the
/// frame limit (the quadratic reader took 48 s), here under a generous bound for slow machines.
#[test]
fn many_csv_frames_are_refused_by_the_frame_limit() {
    let dir = scratch("csv-frames");
    let mut text = String::from("frame,bird,x,y\n");
    for f in 0..100_001 {
        text += &format!("{f},0,{},{}\n", 100 + f % 7, 200);
    }
    std::fs::write(dir.join("many.csv"), text).unwrap();
    let (o, cpu) = run_capped(
        &dir,
        2_000_000,
        None,
        &["extract", "many.csv", "-o", "p.json", "--wingspan-px", "30"],
    );
    assert_refused(&o, "100001 annotated frames, at most 100000", "many frames");
    assert!(cpu < Duration::from_secs(30), "used {cpu:?} of CPU");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `-o x.gif` naming an existing directory is refused (it used to fill it with PNG frames).
#[test]
fn the_format_follows_the_name() {
    let dir = scratch("dir-named-gif");
    std::fs::create_dir(dir.join("x.gif")).unwrap();
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    let o = run_in(&dir, &["render", &anim, "-o", "x.gif"]);
    assert_refused(&o, "-o: x.gif: is an existing directory", "x.gif dir");
    assert!(names(&dir.join("x.gif")).is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Messages quote file content safely: a newline or terminal escape in a CSV header stays on one
/// line as an escape, a 10 MB field is cut, 1e308 is not printed with 300 digits.
#[test]
fn messages_quote_file_content_safely() {
    let dir = scratch("messages");
    std::fs::write(
        dir.join("esc.csv"),
        "frame,bird,\"x\nq\u{1b}[2J\u{7}\",y\n0,0,1,2\n",
    )
    .unwrap();
    let o = run_in(&dir, &["extract", "esc.csv", "-o", "p.json"]);
    assert_usage_error_in("control characters in a CSV header", &o, &["esc.csv"]);
    let e = stderr(&o);
    assert!(!e.contains('\u{1b}') && !e.contains('\u{7}'), "{e:?}");

    let long = format!("frame,bird,x,y\n0,0,{},2\n", "9".repeat(10_000_000));
    std::fs::write(dir.join("long.csv"), long).unwrap();
    let o = run_in(&dir, &["extract", "long.csv", "-o", "p.json"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{}", &e[..e.len().min(500)]);
    assert!(e.len() < 1000, "{} bytes of message", e.len());

    let o = run_in(
        &dir,
        &[
            "render",
            &repo_file("tests/data/flock_small.json")
                .display()
                .to_string(),
            "-o",
            "a.gif",
            "--wingspan-px",
            "1e308",
        ],
    );
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.len() < 300, "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Found probing further: a DLTdv header of 200 000 points was matched quadratically (minutes)
/// before the bird limit; it is now refused while the header is read.
#[test]
fn a_wide_dltdv_header_is_refused_at_once() {
    let dir = scratch("wide-dltdv");
    let mut cols = Vec::new();
    for n in 1..=200_000 {
        cols.push(format!("pt{n}_cam1_X"));
        cols.push(format!("pt{n}_cam1_Y"));
    }
    let ones = vec!["1"; cols.len()].join(",");
    std::fs::write(
        dir.join("wide.csv"),
        format!("{}\n{ones}\n", cols.join(",")),
    )
    .unwrap();
    let (o, cpu) = run_capped(
        &dir,
        1_000_000,
        None,
        &["extract", "wide.csv", "-o", "p.json", "--wingspan-px", "30"],
    );
    assert_refused(
        &o,
        "wide.csv: header: more than 1000 points per camera",
        "wide header",
    );
    assert!(cpu < Duration::from_secs(10), "used {cpu:?} of CPU");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The flag or file at fault is named (found at the end of the session, on the merged main):
/// `power` on an animation file says what the file is, a negative `initiate` flag reaches the
/// library's check, a vanishing `--fps` and an absurd `--wingspan-px` name their flags.
#[test]
fn the_flag_or_file_at_fault_is_named() {
    let dir = scratch("named");
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    let o = run_in(&dir, &["power", &anim]);
    assert_refused(
        &o,
        "flock_small.json: this is a \"formation-animation/1\" file, not a shape",
        "power on an animation",
    );
    let steady = repo_file("tests/data/initiate_steady_v9.json")
        .display()
        .to_string();
    let o = run_in(
        &dir,
        &["initiate", &steady, "-o", "i.json", "--max-turn-rate", "-1"],
    );
    assert_refused(
        &o,
        "--max-turn-rate: must be a positive number",
        "--max-turn-rate -1",
    );
    let params = repo_file("tests/data/steady_v9_params.json")
        .display()
        .to_string();
    let o = run_in(
        &dir,
        &[
            "steady", &params, "--birds", "9", "--frames", "30", "-o", "a.json", "--fps", "5e-324",
        ],
    );
    assert_refused(&o, "--fps: ", "--fps 5e-324");
    let ex = repo_file("examples_data/barnacle_geese_v.json")
        .display()
        .to_string();
    let o = run_in(
        &dir,
        &["extract", &ex, "-o", "p.json", "--wingspan-px", "1e308"],
    );
    assert_refused(
        &o,
        "--wingspan-px: must be a positive number of pixels, at most",
        "--wingspan-px 1e308",
    );
    assert!(names(&dir).is_empty(), "{:?}", names(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Running out of memory (under `ulimit -v`) ends in exit 2 and one line naming the output and
/// the size, removes the run's temporaries and leaves the old outputs as they were: it was an
/// abort (exit 134) with "memory allocation of 8294400 bytes failed", a backtrace and a
/// temporary left behind.
#[test]
fn running_out_of_memory_is_one_line_and_leaves_the_old_outputs() {
    let dir = scratch("oom");
    let anim = repo_file("tests/data/flock_small.json")
        .display()
        .to_string();
    let example = support::example_arg("barnacle_geese_v.json");
    // A 120-bird animation for the report (8.7 MB; its report needs about 26 MB; the flock_small
    // page fits in 18).
    let o = run_in(
        &dir,
        &[
            "animate",
            &example,
            "--birds",
            "120",
            "--seconds",
            "5",
            "-o",
            "mid.json",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::rename(dir.join("mid.json"), dir.with_extension("mid.json")).unwrap();
    let mid = dir.with_extension("mid.json").display().to_string();
    // A request that cannot fit is refused before the work (the take-off's history at its
    // longest); one that could, but does not, runs out and ends the same clean way.
    const OOM: &[&str] = &["out of memory", "bytes could not be allocated"];
    const UP_FRONT: &[&str] = &["--max-steps: ", "of memory available"];
    // What, memory cap (KiB), arguments, outputs, what the message says.
    type Run<'a> = (&'a str, u64, Vec<&'a str>, &'a [&'a str], &'a [&'a str]);
    let runs: [Run; 4] = [
        (
            "render to a 1920x1080 GIF and a .glb",
            100_000,
            vec![
                "render",
                &anim,
                "--size",
                "1920x1080",
                "-o",
                "a.gif",
                "-o",
                "a.glb",
            ],
            &["a.gif", "a.glb"],
            OOM,
        ),
        (
            "animate 200 birds",
            30_000,
            vec!["animate", &example, "--birds", "200", "-o", "a.json"],
            &["a.json"],
            UP_FRONT,
        ),
        (
            "animate 200 birds for a minute without a take-off",
            30_000,
            vec![
                "animate",
                &example,
                "--birds",
                "200",
                "--seconds",
                "60",
                "--no-initiation",
                "-o",
                "a.json",
            ],
            &["a.json"],
            OOM,
        ),
        (
            "report on a 9 MB animation",
            18_000,
            vec!["report", &mid, "-o", "a.html"],
            &["a.html"],
            OOM,
        ),
    ];
    for (what, cap, args, outputs, needles) in runs {
        for o in outputs {
            std::fs::write(dir.join(o), VICTIM).unwrap();
        }
        let (o, _) = run_capped(&dir, cap, None, &args);
        let err = stderr(&o);
        assert_eq!(support::code(&o), 2, "{what}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{what}: {err}");
        assert!(
            err.starts_with("error: ") && needles.iter().all(|n| err.contains(n)),
            "{what}: {err}"
        );
        for o in outputs {
            assert_eq!(std::fs::read(dir.join(o)).unwrap(), VICTIM, "{what}: {o}");
        }
        let mut want: Vec<String> = outputs.iter().map(|s| s.to_string()).collect();
        want.sort();
        assert_eq!(names(&dir), want, "{what}: temporaries left");
        for o in outputs {
            std::fs::remove_file(dir.join(o)).unwrap();
        }
    }
    std::fs::remove_file(dir.with_extension("mid.json")).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}
