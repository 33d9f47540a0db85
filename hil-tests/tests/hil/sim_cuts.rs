//! The simulator's power cut always cuts: `taut-sim`'s run (the library's
//! `session`) stops at the asked cycle, to the instruction, for a few
//! hundred seeded cut times on the string-art job and on a plotter's print
//! from the card, and a cut on text comes however long its delay.

use hil_tests::sim::sdcard::{SdCard, SdImage};
use hil_tests::sim::session::{Cut, Ending, Plan, Session};
use hil_tests::sim::Sim;
use hil_tests::{send_ok, soak_or, Rng};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

static NEVER: AtomicBool = AtomicBool::new(false);

/// The longest instruction (a call through EIND) takes 5 cycles.
const LONGEST_INSTRUCTION: u64 = 5;

fn run(sim: &mut Sim, plan: &Plan) -> Ending {
    Session::new(sim, plan)
        .run(plan, None, &NEVER, |_, _| {})
        .unwrap()
}

/// The machine stopped where the cut was asked, and says so.
fn assert_cut_at(sim: &Sim, ending: &Ending, cycle: u64, what: &str) {
    assert_eq!(*ending, Ending::PowerCut { cycle }, "{what}");
    let stopped = sim.cycles();
    assert!(
        stopped >= cycle && stopped - cycle <= LONGEST_INSTRUCTION,
        "{what}: asked for cycle {cycle}, stopped at {stopped}"
    );
    assert!(ending
        .words()
        .starts_with(&format!("power cut at cycle {cycle}")));
}

fn string_art() -> Sim {
    let mut sim = hil_tests::machine();
    let card = SdImage::from_path(&hil_tests::sample_card_dir()).unwrap();
    sim.insert_sd(SdCard::new(card));
    sim
}

#[test]
fn cuts_during_the_string_art_job_come_at_their_cycle() {
    let mut rng = Rng::new(0x5EED_C075);
    let runs = soak_or(600, 150);
    for k in 0..runs {
        // Whole seconds (where a float once missed) and any cycle.
        let cycle = match k % 4 {
            0 => 16_000_000 * (1 + rng.below(2)),
            _ => 320_000 + rng.below(2 * 16_000_000),
        };
        let mut sim = string_art();
        let plan = Plan {
            cut: Some(Cut::At(cycle)),
            auto_confirm: true,
            ..Plan::default()
        };
        let ending = run(&mut sim, &plan);
        assert_cut_at(&sim, &ending, cycle, &format!("run {k}"));
    }
}

#[test]
fn cuts_during_a_plotter_print_from_the_card_come_at_their_cycle() {
    let star = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/plotter/star.gcode"),
    )
    .unwrap();
    let mut rng = Rng::new(0x9107_7E12);
    let runs = soak_or(400, 100);
    for k in 0..runs {
        let mut sim = hil_tests::boot_machine();
        sim.insert_sd(SdCard::new(hil_tests::card(&[("star.gcode", &star)])));
        for line in ["$machine=flatbed", "$homing_at_start=0", "M17"] {
            send_ok(&mut sim, line, Duration::from_secs(1));
        }
        hil_tests::wait_for(&mut sim, "MiB FAT", Duration::from_secs(3));
        send_ok(&mut sim, "M23 star.gcode", Duration::from_secs(1));
        send_ok(&mut sim, "M24", Duration::from_secs(1));
        let now = sim.cycles();
        let plan = match k % 3 {
            // On the print's own words, however long after.
            0 => Plan {
                cut: Some(Cut::On {
                    text: "File selected".into(),
                    delay: rng.below(2 * 16_000_000),
                }),
                ..Plan::default()
            },
            _ => Plan {
                cut: Some(Cut::At(now + rng.below(2 * 16_000_000))),
                ..Plan::default()
            },
        };
        let ending = run(&mut sim, &plan);
        let cycle = match (&plan.cut, &ending) {
            (Some(Cut::At(c)), _) => *c,
            (_, Ending::PowerCut { cycle }) => *cycle,
            _ => panic!("run {k}: {ending:?}"),
        };
        if let Some(Cut::On { delay, .. }) = plan.cut {
            // "File selected" came before the run began: seen at its start.
            assert_eq!(cycle, now + delay, "run {k}");
        }
        assert_cut_at(&sim, &ending, cycle, &format!("run {k}"));
    }
}

/// A delay far past every other ending (the 5 s limit, the job's end): the
/// run lasts until the cut. Text that never comes is an ending of its own.
#[test]
fn a_cut_on_text_outlasts_the_limit_and_text_that_never_comes_is_an_error() {
    let mut sim = string_art();
    let plan = Plan {
        limit: Some(16_000_000),
        cut: Some(Cut::On {
            text: "state:".into(),
            delay: 6 * 16_000_000,
        }),
        auto_confirm: false,
        file_sent: false,
    };
    let ending = run(&mut sim, &plan);
    let Ending::PowerCut { cycle } = ending else {
        panic!("{ending:?}")
    };
    assert!(cycle > 6 * 16_000_000, "{cycle}");
    assert_cut_at(&sim, &ending, cycle, "state: + 6 s");

    let mut sim = string_art();
    let plan = Plan {
        limit: Some(16_000_000),
        cut: Some(Cut::On {
            text: "never said".into(),
            delay: 0,
        }),
        ..Plan::default()
    };
    let ending = run(&mut sim, &plan);
    assert_eq!(
        ending,
        Ending::CutMissed {
            text: "never said".into()
        }
    );
    assert_eq!(ending.exit_code(), 1);
}
