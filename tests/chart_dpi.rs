//! `plot --dpi`: a PNG chart for print is the same chart drawn larger (the layout of the screen
//! chart, every length scaled), with its resolution recorded in a `pHYs` chunk; SVG charts do not
//! change; a resolution outside 50–600 dpi is refused naming `--dpi`.

mod support;

use support::{bin, code, s, scratch, stderr};

fn chunk<'a>(png: &'a [u8], kind: &[u8; 4]) -> Option<&'a [u8]> {
    let mut at = 8;
    while at + 8 <= png.len() {
        let len = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        if &png[at + 4..at + 8] == kind {
            return Some(&png[at + 8..at + 8 + len]);
        }
        at += 12 + len;
    }
    None
}

#[test]
fn a_chart_at_300_dpi_is_the_screen_chart_drawn_larger() {
    let d = scratch("chart-dpi");
    let plot = |out: &str, dpi: Option<&str>| {
        let mut c = bin();
        c.args([
            "plot",
            "wingbeat",
            "--species",
            "goose",
            "-o",
            s(&d.join(out)),
            "--quiet",
        ]);
        if let Some(v) = dpi {
            c.args(["--dpi", v]);
        }
        c.output().unwrap()
    };
    for (out, dpi) in [
        ("a.png", None),
        ("b.png", Some("300")),
        ("a.svg", None),
        ("b.svg", Some("300")),
    ] {
        let o = plot(out, dpi);
        assert_eq!(code(&o), 0, "{out}: {}", stderr(&o));
    }
    let screen = image::open(d.join("a.png")).unwrap().to_rgb8();
    let print = image::open(d.join("b.png")).unwrap().to_rgb8();
    // 300 / 96 = 3.125 times larger on each side.
    assert_eq!(
        print.dimensions(),
        (
            (screen.width() as f64 * 3.125).round() as u32,
            (screen.height() as f64 * 3.125).round() as u32
        )
    );
    // The resolution is recorded (pixels per metre, unit metre); the screen chart has none.
    let bytes = std::fs::read(d.join("b.png")).unwrap();
    let phys = chunk(&bytes, b"pHYs").expect("a pHYs chunk");
    assert_eq!(u32::from_be_bytes(phys[0..4].try_into().unwrap()), 11811);
    assert_eq!(phys[8], 1);
    assert!(chunk(&std::fs::read(d.join("a.png")).unwrap(), b"pHYs").is_none());
    // The same picture: the print chart shrunk back to the screen size differs little.
    let small = image::imageops::resize(
        &print,
        screen.width(),
        screen.height(),
        image::imageops::FilterType::Triangle,
    );
    let diff: f64 = small
        .pixels()
        .zip(screen.pixels())
        .map(|(a, b)| {
            (0..3)
                .map(|k| (a[k] as f64 - b[k] as f64).abs())
                .sum::<f64>()
        })
        .sum::<f64>()
        / (3.0 * screen.width() as f64 * screen.height() as f64);
    assert!(diff < 12.0, "mean difference {diff:.1} levels");
    // SVG is resolution-free.
    assert_eq!(
        std::fs::read(d.join("a.svg")).unwrap(),
        std::fs::read(d.join("b.svg")).unwrap()
    );
    for bad in ["5000", "0", "nan"] {
        let o = plot("c.png", Some(bad));
        let e = stderr(&o);
        assert_eq!(code(&o), 2, "{bad}: {e}");
        assert!(e.contains("--dpi") && e.lines().count() == 1, "{bad}: {e}");
        assert!(!d.join("c.png").exists());
    }
    std::fs::remove_dir_all(&d).unwrap();
}
