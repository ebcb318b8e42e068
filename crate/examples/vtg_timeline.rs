//! Prints when `vtg`'s progress moves (elapsed seconds and fraction done), to see which stage of
//! a run takes the time, e.g.
//! `cargo run --release --example vtg_timeline -- ../shared/corpus/curaengine-4.13.0_extruder-idler-x2.5_large.gcode`;
//! set `NO_DYNAMICS=1` for the run without the dynamics model.

use std::time::Instant;

mod common;

fn main() {
    let Some((path, input, _)) = common::file_and_runs("vtg_timeline", 1) else {
        return;
    };
    let options = quietpath::vtg::VtgOptions {
        dynamics: std::env::var_os("NO_DYNAMICS").is_none(),
        ..Default::default()
    };
    let start = Instant::now();
    let mut last = -1.0;
    let report = quietpath::vtg::vtg_with_progress(&input, &options, &mut |f| {
        // Progress moves in small steps within a stage: one line per hundredth, and any step
        // back (a bar that went back would mislead).
        let at = start.elapsed().as_secs_f64();
        if f < last {
            println!("{at:7.2} s  {f:.3}  back from {last:.3}");
            last = f;
        } else if f - last >= 0.01 {
            println!("{at:7.2} s  {f:.3}");
            last = f;
        }
        true
    });
    match report {
        Ok(r) => println!(
            "{:7.2} s  done: {}",
            start.elapsed().as_secs_f64(),
            r.message.unwrap_or_default()
        ),
        Err(e) => eprintln!("{path}: {e}"),
    }
}
