//! Wall-clock and CPU time of the simulator's hot paths, for a machine shared with other
//! work (CPU time is what one uncontended core would take):
//! `cargo run --release -p nesy-sim --example timing`.

use std::time::Instant;

use nesy_sim::api::{Direction, RobotApi};
use nesy_sim::perception::observer::observe;
use nesy_sim::perception::render::{VIEW_SIZE, render_views};
use nesy_sim::scene::SceneSpec;
use nesy_sim::world::Sim;

fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn scene(name: &str) -> SceneSpec {
    let path = nesy_testkit::workspace_root()
        .join("fixtures/scenes")
        .join(format!("{name}.json"));
    SceneSpec::from_file(&path).expect("fixture scene")
}

/// Runs `f` `n` times; returns (wall, cpu) seconds per run.
fn time<T>(n: usize, mut f: impl FnMut() -> T) -> (f64, f64) {
    let (w0, c0) = (Instant::now(), cpu_seconds());
    for _ in 0..n {
        std::hint::black_box(f());
    }
    (
        w0.elapsed().as_secs_f64() / n as f64,
        (cpu_seconds() - c0) / n as f64,
    )
}

fn main() {
    let spec = scene("pick_place_finger");
    let mut sim_seconds = 0.0;
    let (wall, cpu) = time(10, || {
        let mut sim = Sim::new(&spec).expect("scene");
        let start = sim.time();
        sim.move_gripper_to("red_cube", Direction::Down, 0.015)
            .expect("reach");
        sim.close_gripper().expect("close");
        let c = sim.get_obj_pos("toy_box").expect("box");
        sim.move_to_position([c[0], c[1], 0.6], Direction::Down, 0.12, 0.0)
            .expect("carry");
        sim.open_gripper().expect("open");
        sim_seconds = sim.time() - start;
    });
    println!(
        "pick-and-place: {sim_seconds:.2} s simulated; wall {:.1} ms (RTF {:.0}x), cpu {:.1} ms (RTF {:.0}x) incl. building the world",
        wall * 1e3,
        sim_seconds / wall,
        cpu * 1e3,
        sim_seconds / cpu
    );
    // A whole high-complexity expert episode (all four subtasks, 15 loose objects).
    let files = nesy_sim::tasks::scenario::generate_suite();
    let high = nesy_sim::tasks::scenario::find(&files, "comb_high_00_s0")
        .expect("scenario")
        .generate(nesy_sim::tasks::scenario::Side::Source)
        .expect("scene")
        .scene;
    let mut episode_seconds = 0.0;
    let (wall, cpu) = time(3, || {
        let episode = nesy_sim::tasks::experts::run_scene(&high).expect("episode");
        episode_seconds = episode.sim_time;
    });
    println!(
        "expert episode comb_high_00_s0 (source): {episode_seconds:.1} s simulated; wall {:.0} ms (RTF {:.0}x), cpu {:.0} ms (RTF {:.0}x)",
        wall * 1e3,
        episode_seconds / wall,
        cpu * 1e3,
        episode_seconds / cpu
    );
    let composite = Sim::new(&scene("composite_all_finger")).expect("scene");
    let (wall, cpu) = time(10, || render_views(&composite, VIEW_SIZE, 1));
    println!(
        "render 3 views 384², 1 thread: wall {:.1} ms, cpu {:.1} ms",
        wall * 1e3,
        cpu * 1e3
    );
    let (wall, cpu) = time(10, || render_views(&composite, VIEW_SIZE, 2));
    println!(
        "render 3 views 384², 2 threads: wall {:.1} ms, cpu (both threads) {:.1} ms",
        wall * 1e3,
        cpu * 1e3
    );
    let (wall, cpu) = time(2000, || observe(&composite));
    println!(
        "observe ({} parts): wall {:.1} µs, cpu {:.1} µs",
        composite.parts().len(),
        wall * 1e6,
        cpu * 1e6
    );
}
