//! Times one key-shape solve of the bench problem for the sizes given on the command line
//! (development aid for docs/performance.md): `cargo run --release --example time_solve -- 1000 10000`.
use formation::aero;
use formation::keyshape::{solve, SolveOptions};

fn main() {
    for arg in std::env::args().skip(1) {
        let n: usize = arg.parse().expect("a number of birds");
        let mut x = vec![0.0];
        let mut y = vec![0.0];
        for k in 1..n {
            let rank = k.div_ceil(2) as f64;
            let side = if k % 2 == 1 { 1.0 } else { -1.0 };
            x.push(side * rank * 1.05);
            y.push(rank * 0.6 + 0.05 * (k as f64 * 1.7).sin());
        }
        let t = std::time::Instant::now();
        let xi = aero::power_reduction(&x, &y).unwrap().xi;
        let t_model = t.elapsed();
        let guess: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(k, v)| v + 0.3 * (k as f64 * 2.3).cos())
            .collect();
        let t = std::time::Instant::now();
        let mut opts = SolveOptions::default();
        if let Ok(v) = std::env::var("DENSE_LIMIT") {
            opts.dense_limit = v.parse().unwrap();
        }
        if let Ok(v) = std::env::var("BAND_SPAN") {
            opts.band_span = v.parse().unwrap();
        }
        if std::env::var("NO_CHECK").is_ok() {
            opts.check_reachable = false;
        }
        let rep = solve(&x, &xi, Some(&guess), &opts).unwrap();
        println!(
            "N = {n}: solve {:.3} s ({} evaluations, residual {:.1e}, {}); one evaluation of e {:.3} s",
            t.elapsed().as_secs_f64(),
            rep.evaluations,
            rep.residual,
            rep.termination,
            t_model.as_secs_f64()
        );
    }
}
