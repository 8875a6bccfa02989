//! The Lissaman & Shollenberger-type lifting-line model (`aero::lissaman`): mirror symmetry, a
//! lone bird, savings that fall with distance, Munk's stagger theorem, agreement with Hummel's
//! model far apart, and the shape-level sums behind `--aero-model lissaman`.

mod support;

use formation::aero::{lissaman, AeroModel, AeroOptions, Wake};
use support::{code, data, example_arg, run, s, scratch, stderr, stdout};

fn hummel() -> AeroOptions {
    AeroOptions::default()
}

fn ls() -> AeroOptions {
    AeroOptions {
        model: AeroModel::Lissaman,
        ..AeroOptions::default()
    }
}

const XS: &[f64] = &[
    0.0, 0.4, 0.9, 1.0, 1.05, 1.2, 1.5, 2.0, 3.0, 5.0, 10.0, 40.0,
];
const YS: &[f64] = &[-30.0, -2.0, -0.5, -0.13, 0.13, 0.5, 1.24, 5.0, 100.0];

#[test]
fn mirror_symmetry_of_pairs_and_shapes() {
    for &x in XS {
        for &y in YS {
            for z in [0.0, 0.06] {
                assert_eq!(lissaman::saving(x, y, z), lissaman::saving(-x, y, z));
            }
        }
    }
    // A V and its mirror image: each bird saves what its mirror bird saves.
    let x = [0.0, -0.9, 0.85, -1.8, 1.75, -2.7];
    let y = [0.0, 1.2, 1.3, 2.4, 2.5, 3.7];
    let mx: Vec<f64> = x.iter().map(|v| -v).collect();
    let (a, b) = (
        ls().power_reduction_3d(&x, &y, &[0.0; 6]).unwrap(),
        ls().power_reduction_3d(&mx, &y, &[0.0; 6]).unwrap(),
    );
    for i in 0..6 {
        assert!((a.e[i] - b.e[i]).abs() < 1e-15, "bird {i}");
    }
}

#[test]
fn a_lone_bird_saves_nothing() {
    assert_eq!(lissaman::power(&[0.3], &[1.0], &[0.0], 0.125), vec![0.0]);
    assert!(ls().power_reduction_3d(&[0.0], &[0.0], &[0.0]).is_err());
    // A partner far away saves it nothing either.
    for y in [-1e4, 0.0, 1e4] {
        assert!(lissaman::saving(1e4, y, 0.0).abs() < 1e-8);
    }
}

#[test]
fn savings_fall_with_distance() {
    // Outboard of the wingtips the saving falls as the gap grows, at every stagger, and as the
    // bird moves ahead of the other.
    for &y in YS {
        let mut last = f64::INFINITY;
        for k in 0..60 {
            let x = 1.0 + 0.05 * k as f64;
            let v = lissaman::saving(x, y, 0.0);
            assert!(v < last && v > 0.0, "x={x} y={y}: {v} after {last}");
            last = v;
        }
    }
    for &x in &[1.0, 1.5, 3.0] {
        let mut last = f64::INFINITY;
        for k in 0..40 {
            let y = 20.0 - k as f64;
            let v = lissaman::saving(x, y, 0.0);
            assert!(v < last, "x={x} y={y}");
            last = v;
        }
    }
    // And with height: a bird above or below the other's sheet gets less.
    for &x in &[1.0, 1.2, 2.0] {
        assert!(lissaman::saving(x, 1.24, 0.1) < lissaman::saving(x, 1.24, 0.0));
        assert!(lissaman::saving(x, 1.24, 0.3) < lissaman::saving(x, 1.24, 0.1));
    }
}

#[test]
fn munk_stagger_theorem() {
    // e_ij + e_ji = 2 e_ij(y = 0) whatever the stagger (and the height): the near-field parts
    // of the two birds cancel. Numerically to the quadrature's accuracy.
    let mut worst: f64 = 0.0;
    for &x in XS {
        for &y in YS {
            if x < 1.0 && y.abs() < 0.125 {
                continue;
            }
            for z in [0.0, 0.06, -0.2] {
                let pair = lissaman::saving(x, y, z) + lissaman::saving(-x, -y, -z);
                let abreast = 2.0 * lissaman::saving(x, 0.0, z);
                let err = (pair - abreast).abs();
                worst = worst.max(err);
                assert!(err < 1e-4, "x={x} y={y} z={z}: {pair} vs {abreast}");
            }
        }
    }
    println!("worst departure from Munk's theorem: {worst:.2e}");
    // At shape level: E does not change when the birds move fore and aft.
    let x = [0.0, -1.1, 1.1, -2.2, 2.2];
    let e1: f64 = lissaman::power(&x, &[0.0, 1.0, 1.0, 2.0, 2.0], &[], 0.125)
        .iter()
        .sum();
    let e2: f64 = lissaman::power(&x, &[3.0, 0.2, 5.0, 1.0, 9.0], &[], 0.125)
        .iter()
        .sum();
    assert!((e1 - e2).abs() < 1e-4, "{e1} vs {e2}");
}

#[test]
fn agrees_with_hummel_far_apart() {
    // Both wings' far fields are a dipole of moment Γ₀·πb/4: the models agree to leading order
    // in 1/x², and their difference is the next order (the loadings' second moments differ),
    // under 0.1/x² relative at x ≥ 3 (measured: about 0.07/x²).
    for &x in &[3.0, 5.0, 10.0, 20.0, 40.0] {
        for &y in &[-20.0, -2.0, 0.0, 1.24, 5.0, 100.0] {
            let (a, b) = (lissaman::saving(x, y, 0.0), hummel().g(x, y));
            let rel = ((a - b) / b).abs();
            assert!(rel < 0.1 / (x * x), "x={x} y={y}: {a} vs {b} ({rel:.2e})");
        }
    }
    // Far behind and far aside, both are 1/(4x²).
    let x = 40.0;
    let v = lissaman::saving(x, 1e6, 0.0);
    assert!((v * 4.0 * x * x - 1.0).abs() < 1e-3, "{v}");
    // Near the wingtips they differ: Hummel concentrates the wake in two cored vortices π/4
    // apart, the lifting line spreads it over the whole span.
    assert!(lissaman::saving(1.0, 1.24, 0.0) > 1.2 * hummel().g(1.0, 1.24));
}

#[test]
fn shape_sums_follow_the_model_and_the_wake() {
    let x = [0.0, -0.8, 0.8, -1.6, 1.6];
    let y = [0.0, 1.24, 1.24, 2.48, 2.48];
    let z = [0.0, 0.06, -0.06, 0.0, 0.12];
    let planar = ls().power_reduction_3d(&x, &y, &z).unwrap();
    let flat = ls().power_reduction_3d(&x, &y, &[0.0; 5]).unwrap();
    assert_eq!(planar.e, flat.e, "the planar wake ignores heights");
    let three = AeroOptions {
        wake: Wake::ThreeD,
        ..ls()
    }
    .power_reduction_3d(&x, &y, &z)
    .unwrap();
    assert!(three.total < planar.total);
    let h = hummel().power_reduction_3d(&x, &y, &z).unwrap();
    assert!((h.total - planar.total).abs() > 1e-3, "the models differ");
    // A colliding shape is refused by both.
    assert!(ls()
        .power_reduction_3d(&[0.0, 0.5], &[0.0, 0.01], &[0.0; 2])
        .is_err());
    // The model's name round-trips.
    for m in [AeroModel::Hummel, AeroModel::Lissaman] {
        assert_eq!(m.name().parse::<AeroModel>().unwrap(), m);
    }
    assert!("sideways".parse::<AeroModel>().is_err());
}

#[test]
fn the_flag_changes_the_savings_not_the_motion() {
    let dir = scratch("lissaman-cli");
    let params = data("steady_v9_params.json");
    let steady = |model: &str, out: &std::path::Path| {
        let o = run(&[
            "steady",
            s(&params),
            "--birds",
            "9",
            "--frames",
            "40",
            "--aero-model",
            model,
            "-o",
            s(out),
        ]);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
        (v, stderr(&o) + &stdout(&o))
    };
    let (h, _) = steady("hummel", &dir.join("h.json"));
    let (l, said) = steady("lissaman", &dir.join("l.json"));
    assert!(said.contains("; by lissaman, planar wake: "), "{said}");
    assert_eq!(l["savings_model"]["model"], "lissaman");
    assert!(
        h["savings_model"].get("model").is_none(),
        "Hummel's is the default"
    );
    let (hf, lf) = (
        h["frames"].as_array().unwrap(),
        l["frames"].as_array().unwrap(),
    );
    assert_eq!(hf.len(), lf.len());
    let mut differ = 0;
    for (a, b) in hf.iter().zip(lf) {
        assert_eq!(a["x"], b["x"]);
        assert_eq!(a["y"], b["y"]);
        // Each frame's savings are the model's at the frame's positions.
        let e = b["e"].as_array().unwrap();
        let sum: f64 = e.iter().map(|v| v.as_f64().unwrap()).sum();
        let xi0 = b["xi"][0].as_f64().unwrap();
        // e and xi are stored to 10⁻⁶.
        assert!((xi0 - e[0].as_f64().unwrap() / sum).abs() < 5e-6);
        differ += usize::from(a["e"] != b["e"]);
    }
    assert_eq!(differ, hf.len());
    // `power`: the main numbers are the lifting lines', named; the band holds both models.
    let o = run(&[
        "power",
        &example_arg("v9_shape.json"),
        "--aero-model",
        "lissaman",
        "--json",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["model"]["name"], "lissaman");
    assert!(v["model"].get("core_radius").is_none());
    assert_eq!(v["sensitivity"].as_array().unwrap().len(), 0);
    let band = v["band"].as_array().unwrap();
    assert_eq!(
        band.len(),
        12,
        "5 cores x 2 wakes of Hummel's, 2 wakes of the lifting lines"
    );
    let shape: formation::Shape =
        serde_json::from_str(&std::fs::read_to_string(support::example("v9_shape.json")).unwrap())
            .unwrap();
    let lib = ls()
        .power_reduction_3d(&shape.xs(), &shape.ys(), &shape.zs())
        .unwrap();
    for (b, e) in v["birds"].as_array().unwrap().iter().zip(&lib.e) {
        assert_eq!(b["saving"].as_f64().unwrap(), *e);
    }
    assert!(band
        .iter()
        .any(|b| b["model"] == "lissaman" && b["flock_saving"] == v["flock_saving"]));
    let _ = std::fs::remove_dir_all(&dir);
}
