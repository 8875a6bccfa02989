//! Helpers shared by the integration tests: running the built binary, scratch directories, paths
//! of the shipped examples and fixtures, the usage-error assertion (exit 2, one line naming the
//! culprit), and a SHA-256 for byte-identity checks. Each test file includes it with
//! `mod support;`; not every file uses every helper.

#![allow(dead_code)]

pub mod clearance;
pub mod glb;
pub mod rig;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The path of the built `formation` binary (for `sh -c` wrappers and the like).
pub fn bin_path() -> &'static str {
    env!("CARGO_BIN_EXE_formation")
}

/// The built `formation` binary, ready for arguments.
pub fn bin() -> Command {
    Command::new(bin_path())
}

/// Runs the binary with `args` and returns everything it did.
pub fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run formation")
}

/// Runs the binary with `args` plus `--quiet`: (exit code, stderr).
pub fn run_quiet(args: &[&str]) -> (i32, String) {
    let out = bin()
        .args(args)
        .arg("--quiet")
        .output()
        .expect("run formation");
    (code(&out), stderr(&out))
}

/// Runs `formation --quiet ARGS` with `dir` as the working directory.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    bin()
        .current_dir(dir)
        .arg("--quiet")
        .args(args)
        .output()
        .expect("run formation")
}

/// What the shell prints before the child's CPU times (see [`run_capped`]).
const CPU_MARK: &str = "@@formation-test-cpu@@\n";

/// Runs `formation --quiet ARGS` in `dir` through `sh -c` with a memory cap (`ulimit -v
/// mem_kib`, KiB) and an optional file-size cap (`ulimit -f`, 512-byte blocks). Gives the output
/// and the CPU time (user + system) the run used: unlike the wall-clock time, it does not grow
/// when the machine is loaded or the tests share a core, so a bound on it holds on any CI run.
pub fn run_capped(
    dir: &Path,
    mem_kib: u64,
    fsize: Option<u64>,
    args: &[&str],
) -> (Output, std::time::Duration) {
    let mut script = format!("ulimit -v {mem_kib}; ");
    if let Some(f) = fsize {
        script += &format!("ulimit -f {f}; ");
    }
    // `times` (POSIX) prints the shell's own and then its children's user and system times.
    script += &format!(
        "\"$0\" --quiet \"$@\"; s=$?; printf '{}' >&2; times >&2; exit $s",
        CPU_MARK.replace('\n', "\\n")
    );
    let mut out = Command::new("sh")
        .current_dir(dir)
        // glibc gives a thread that allocates its own arena, reserving 64 MiB of address space
        // that `ulimit -v` counts though it is never used. Whether the signal-cleanup thread gets
        // one before the main thread has taken the room depends on timing: CI once failed a
        // 100 MiB run this way that needs under 60 MiB here. One arena makes the cap measure
        // what the run allocates.
        .env("MALLOC_ARENA_MAX", "1")
        .arg("-c")
        .arg(script)
        .arg(bin_path())
        .args(args)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run formation through sh");
    let text = String::from_utf8_lossy(&out.stderr).into_owned();
    let at = text
        .rfind(CPU_MARK)
        .unwrap_or_else(|| panic!("no CPU times from sh: {text}"));
    let cpu = children_cpu_time(&text[at + CPU_MARK.len()..]);
    out.stderr.truncate(at);
    (out, cpu)
}

/// The children's user + system time from the output of `times` (`0m0.10s 0m0.52s` on its
/// second line; dash prints six decimals, bash three).
fn children_cpu_time(times: &str) -> std::time::Duration {
    let line = times
        .lines()
        .nth(1)
        .unwrap_or_else(|| panic!("unexpected `times` output: {times:?}"));
    let secs: f64 = line
        .split_whitespace()
        .map(|t| {
            let (m, s) = t
                .trim_end_matches('s')
                .split_once('m')
                .unwrap_or_else(|| panic!("unexpected `times` field {t:?}"));
            m.parse::<f64>().unwrap() * 60.0 + s.parse::<f64>().unwrap()
        })
        .sum();
    std::time::Duration::from_secs_f64(secs)
}

/// A clock of the calling thread's CPU time (Linux: `/proc/thread-self/schedstat`, in ns), or
/// of the wall-clock time where that is not available. Bounds on work done in the test process
/// use it: unlike the wall-clock time it does not grow when the machine is loaded or the tests
/// share a core.
pub struct WorkClock {
    start_ns: Option<u64>,
    wall: std::time::Instant,
}

impl WorkClock {
    /// Starts the clock.
    pub fn start() -> Self {
        WorkClock {
            start_ns: thread_cpu_ns(),
            wall: std::time::Instant::now(),
        }
    }

    /// The time on the clock since [`WorkClock::start`].
    pub fn elapsed(&self) -> std::time::Duration {
        match (self.start_ns, thread_cpu_ns()) {
            (Some(a), Some(b)) => std::time::Duration::from_nanos(b.saturating_sub(a)),
            _ => self.wall.elapsed(),
        }
    }
}

/// The calling thread's time on a CPU so far, in nanoseconds (Linux).
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// The exit code, −1 for a signal.
pub fn code(out: &Output) -> i32 {
    out.status.code().unwrap_or(-1)
}

/// Standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Standard output as text.
pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A fresh, empty scratch directory unique to this test process and `name`.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "formation-test-{}-{}",
        std::process::id(),
        name.replace(['/', '\\'], "_")
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch directory");
    dir
}

/// A path as a `&str` argument.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// A file or directory of `examples_data/`.
pub fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples_data")
        .join(name)
}

/// [`example`] as a string argument.
pub fn example_arg(name: &str) -> String {
    example(name).to_string_lossy().into_owned()
}

/// A fixture of `tests/data/`.
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A file of the repository, by its path relative to the repository's root.
pub fn repo_file(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Exit 2 and exactly one line on stderr, starting with `error: `, no panic, containing every
/// `needle`.
pub fn assert_usage_error(out: &Output, needles: &[&str]) {
    assert_usage_error_in("", out, needles);
}

/// [`assert_usage_error`] for one `needle`, with `what` (the case) in every failure message.
pub fn assert_refused(out: &Output, needle: &str, what: &str) {
    assert_usage_error_in(what, out, &[needle]);
}

/// [`assert_usage_error`], with `what` (the case: its arguments, say) in every failure message.
pub fn assert_usage_error_in(what: &str, out: &Output, needles: &[&str]) {
    assert_usage_text(what, code(out), &stderr(out), needles);
}

/// [`assert_usage_error_in`] for a run already reduced to its exit `code` and stderr `err`.
pub fn assert_usage_text(what: &str, code: i32, err: &str, needles: &[&str]) {
    assert_eq!(code, 2, "{what}: exit {code}, stderr: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{what}: one line expected: {err}"
    );
    assert!(err.starts_with("error: "), "{what}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    for n in needles {
        assert!(err.contains(n), "{what}: {err:?} should mention {n:?}");
    }
}

/// SHA-256 of `bytes` as lowercase hex (FIPS 180-4), for comparing outputs with recorded digests
/// that `sha256sum` reproduces.
pub fn sha256_hex(bytes: &[u8]) -> String {
    const K: [u32; 64] = [
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
        0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
        0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
        0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
        0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
        0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
        0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
        0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
        0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
        0xc67178f2,
    ];
    let mut h: [u32; 8] = [
        0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab,
        0x5be0cd19,
    ];
    let mut msg = bytes.to_vec();
    let bit_len = (bytes.len() as u64).wrapping_mul(8);
    msg.push(0x80);
    while msg.len() % 64 != 56 {
        msg.push(0);
    }
    msg.extend_from_slice(&bit_len.to_be_bytes());
    for block in msg.chunks_exact(64) {
        let mut w = [0u32; 64];
        for (i, c) in block.chunks_exact(4).enumerate() {
            w[i] = u32::from_be_bytes([c[0], c[1], c[2], c[3]]);
        }
        for i in 16..64 {
            let s0 = w[i - 15].rotate_right(7) ^ w[i - 15].rotate_right(18) ^ (w[i - 15] >> 3);
            let s1 = w[i - 2].rotate_right(17) ^ w[i - 2].rotate_right(19) ^ (w[i - 2] >> 10);
            w[i] = w[i - 16]
                .wrapping_add(s0)
                .wrapping_add(w[i - 7])
                .wrapping_add(s1);
        }
        let [mut a, mut b, mut c, mut d, mut e, mut f, mut g, mut hh] = h;
        for i in 0..64 {
            let s1 = e.rotate_right(6) ^ e.rotate_right(11) ^ e.rotate_right(25);
            let ch = (e & f) ^ (!e & g);
            let t1 = hh
                .wrapping_add(s1)
                .wrapping_add(ch)
                .wrapping_add(K[i])
                .wrapping_add(w[i]);
            let s0 = a.rotate_right(2) ^ a.rotate_right(13) ^ a.rotate_right(22);
            let maj = (a & b) ^ (a & c) ^ (b & c);
            let t2 = s0.wrapping_add(maj);
            hh = g;
            g = f;
            f = e;
            e = d.wrapping_add(t1);
            d = c;
            c = b;
            b = a;
            a = t1.wrapping_add(t2);
        }
        for (x, y) in h.iter_mut().zip([a, b, c, d, e, f, g, hh]) {
            *x = x.wrapping_add(y);
        }
    }
    h.iter().map(|v| format!("{v:08x}")).collect()
}

/// Runs the binary with `args`: (exit code, stdout, stderr).
pub fn run_full(args: &[&str]) -> (i32, String, String) {
    let out = run(args);
    (code(&out), stdout(&out), stderr(&out))
}

/// The `examples_data/` directory.
pub fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data")
}
