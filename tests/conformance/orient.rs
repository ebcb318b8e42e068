//! Conformance of `orient` on the real corpus: the 5-axis file of Zhang et al. (table-tilting B,
//! rotary C, multi-turn C) smoothed with the defaults.

use quietpath::orient::{self, Kinematics, Pose, SmoothOptions};
use quietpath::vec3;
use quietpath_conformance::corpus_dir;

const FILE: &str = "multiaxis-xyzbc_zhang-ral2021_model1.gcode";

fn poses(gcode: &[u8]) -> Vec<(u32, Pose, bool)> {
    let path = quietpath::path::extract(gcode, &Default::default(), false).expect("extract");
    path.moves
        .iter()
        .map(|m| {
            let pose = Pose {
                xyz: [m.to[0], m.to[1], m.to[2]],
                rot: [m.to[5], m.to[6]],
            };
            (m.line, pose, m.is_extruding() && m.length_mm <= 5.0)
        })
        .collect()
}

#[test]
fn five_axis_corpus_file_is_smoothed_within_the_cone() {
    let input = std::fs::read(corpus_dir().join(FILE)).expect("corpus file");
    let options = SmoothOptions::default();
    let report = orient::smooth(&input, &options).expect("smooth");
    let half = options.cone_deg / 2.0;
    println!(
        "{FILE}: {} points, {} runs, {} changed, {} corrected, max angle {:.3}°, roughness {:.5} -> {:.5} ({:.1}%)",
        report.points,
        report.runs,
        report.changed,
        report.corrected,
        report.max_angle_to_original_deg,
        report.before.roughness,
        report.after.roughness,
        100.0 * report.roughness_reduction
    );
    assert!(report.points > 30_000);
    assert!(report.max_angle_to_original_deg <= half);
    // Runs are cut only by travel and tool-tip jumps now (47 runs, not the 414 the machine-XYZ
    // rule made): the pole crossings of Zhang's generator, which carry most of the file's
    // orientation roughness, are inside runs, smoothed in joint space, and measured.
    // Done when: roughness falls by at least 30 % (82 %), both rotary axes' peaks fall.
    assert!(report.runs < 100, "{}", report.runs);
    assert!(
        report.roughness_reduction >= 0.3,
        "{}",
        report.roughness_reduction
    );
    for (b, a) in report.before.rotary.iter().zip(&report.after.rotary) {
        println!(
            "{}: peak velocity {:.0} -> {:.0} °/s, acceleration {:.0} -> {:.0} °/s², jerk {:.0} -> {:.0} °/s³",
            a.axis,
            b.max_velocity_deg_s,
            a.max_velocity_deg_s,
            b.max_acceleration_deg_s2,
            a.max_acceleration_deg_s2,
            b.max_jerk_deg_s3,
            a.max_jerk_deg_s3
        );
    }
    // On the tool tip's schedule (the same for both), both rotary axes' peaks fall.
    for (b, a) in report.before.rotary.iter().zip(&report.after.rotary) {
        assert!(a.max_velocity_deg_s < b.max_velocity_deg_s, "{}", a.axis);
        assert!(
            a.max_acceleration_deg_s2 < b.max_acceleration_deg_s2,
            "{}",
            a.axis
        );
        assert!(a.max_jerk_deg_s3 < b.max_jerk_deg_s3, "{}", a.axis);
    }

    // Same motion lines; every line that is not an extruding G1 byte-identical.
    let out = &report.output;
    let a: Vec<&[u8]> = input.split(|&b| b == b'\n').collect();
    let b: Vec<&[u8]> = out.split(|&b| b == b'\n').collect();
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        if !x.starts_with(b"G1") {
            assert_eq!(x, y);
        } else {
            assert!(y.starts_with(b"G1"));
        }
    }

    // Read back: same tool tip in the workpiece frame, tool vector within γ/2 exactly, and the
    // turntable never jumps by half a turn or more inside a printed section.
    let kin = Kinematics::default();
    let (before, after) = (poses(&input), poses(out));
    assert_eq!(before.len(), after.len());
    let mut worst = 0.0f64;
    let mut prev: Option<(f64, f64)> = None;
    for ((la, pa, printing), (lb, pb, _)) in before.iter().zip(&after) {
        assert_eq!(la, lb);
        let tip = vec3::norm(vec3::sub(kin.tip(pa), kin.tip(pb)));
        assert!(tip <= 1e-3, "line {la}: tip moved {tip} mm");
        let ang = vec3::deg(vec3::angle(
            kin.tool_vector(pa.rot),
            kin.tool_vector(pb.rot),
        ));
        worst = worst.max(ang);
        assert!(ang <= half, "line {la}: {ang}°");
        if *printing {
            if let Some((ca, cb)) = prev {
                let (da, db) = ((pa.rot[1] - ca).abs(), (pb.rot[1] - cb).abs());
                assert!(
                    db < 180.0 || db <= da,
                    "line {la}: C steps {db}° (input {da}°)"
                );
            }
        }
        prev = Some((pa.rot[1], pb.rot[1]));
    }
    assert!((worst - report.max_angle_to_original_deg).abs() < 1e-9);
}
