//! Savings in physical terms (issue 12) through the binary: `animate` writes e (the saving) and ξ
//! as numbers in every frame of the JSON animation and every row of the CSV, the take-off
//! included.

mod support;

use support::{bin, example, scratch};

#[test]
fn every_frame_and_csv_row_carries_numeric_e_and_xi() {
    let dir = scratch("savings");
    let input = example("barnacle_geese_v.json");
    let (csv, json) = (dir.join("flock.csv"), dir.join("flock.json"));
    let out = bin()
        .args([
            "animate",
            input.to_str().unwrap(),
            "--birds",
            "14",
            "--seconds",
            "4",
            "--quiet",
        ])
        .args(["-o", csv.to_str().unwrap(), "-o", json.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let anim: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let stages = anim["stages"].as_array().unwrap();
    assert_eq!(stages[0]["name"], "initiation");
    let takeoff_end = stages[0]["end"].as_u64().unwrap() as usize;
    assert!(takeoff_end > 0);
    let frames = anim["frames"].as_array().unwrap();
    for (k, f) in frames.iter().enumerate() {
        let e = f["e"]
            .as_array()
            .unwrap_or_else(|| panic!("frame {k}: no e"));
        let xi = f["xi"]
            .as_array()
            .unwrap_or_else(|| panic!("frame {k}: no xi"));
        assert_eq!(e.len(), 14);
        assert!(
            e.iter()
                .chain(xi)
                .all(|v| v.as_f64().is_some_and(f64::is_finite)),
            "frame {k}"
        );
        let sum: f64 = xi.iter().map(|v| v.as_f64().unwrap()).sum();
        // Each ξ is stored to 10⁻⁶.
        assert!(
            (sum - 1.0).abs() < 0.5e-6 * 14.0 + 1e-9,
            "frame {k}: Σξ = {sum}"
        );
    }
    // The saving at the end of the take-off is the formation's, well above that at its start.
    let mean = |k: usize| {
        let e = frames[k]["e"].as_array().unwrap();
        e.iter().map(|v| v.as_f64().unwrap()).sum::<f64>() / 14.0
    };
    assert!(
        mean(takeoff_end - 1) > mean(0),
        "{} vs {}",
        mean(takeoff_end - 1),
        mean(0)
    );

    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "frame,t,bird,x,y,z,heading,speed,e,xi,stage,formation,rank,leader,lateral,behind,wing_phase,bank,saving_total,qx,qy,qz,qw,pitch"
    );
    let mut rows = 0;
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        for c in &cells[8..10] {
            assert!(c.parse::<f64>().is_ok_and(f64::is_finite), "row {line:?}");
        }
        rows += 1;
    }
    assert_eq!(rows, frames.len() * 14);
    let _ = std::fs::remove_dir_all(&dir);
}
