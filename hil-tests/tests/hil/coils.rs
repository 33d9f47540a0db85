//! Seed 001's drum plotter as built: two 28BYJ-48s on ULN2003 boards,
//! half-stepped through their coils (`$x_driver=uln2003`, the drum's
//! default) from the same planner and step interrupt as every machine.
//! Its drawings are read back from the coil inputs alone (`x_in1`..`y_in4`)
//! and must be the STEP/DIR build's, half-step for half-step; no input
//! change a motor could not follow (the end check of every test); the
//! coils released once the machine stands and back at the same phase.

use hil_tests::drawing::{drawing, PenWords};
use hil_tests::sim::{Reply, Sim};
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, track};
use std::time::Duration;
use taut_logic::config::{MachineConfig, COIL_MAX_RATE};
use taut_logic::machine::Machine;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(120));
}

/// The pen's path in X, Y steps: one entry per step of either motor.
fn path(sim: &Sim) -> Vec<[i64; 2]> {
    track(sim).into_iter().map(|(_, s)| [s[0], s[1]]).collect()
}

/// The drum at X40 Y40, on its coils or (`coils` false) on STEP/DIR
/// drivers, draws `$T5`, `$T7` and the test drawing.
fn drum_draws(coils: bool) -> Sim {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=drum");
    if !coils {
        send(&mut sim, "$x_driver=stepdir");
        send(&mut sim, "$y_driver=stepdir");
    }
    send(&mut sim, "G0 X40 Y40");
    for pattern in ["$T5", "$T7"] {
        send(&mut sim, pattern);
        send(&mut sim, "M400");
    }
    for line in drawing(PenWords::Spindle, [40.0, 40.0], 60.0, 20.0).lines {
        send(&mut sim, &line);
    }
    sim.run_for(Duration::from_millis(400));
    sim
}

#[test]
fn the_drum_draws_on_its_coils_what_step_dir_drivers_draw() {
    let on_coils = drum_draws(true);
    let on_drivers = drum_draws(false);
    let (a, b) = (path(&on_coils), path(&on_drivers));
    // Nothing on the STEP pins of the coil build, nothing on the coils of
    // the other.
    assert_eq!(on_coils.probed("base_step").edge_count(), 0);
    assert_eq!(on_drivers.coil_track(0).steps.len(), 0);
    assert!(a.len() > 20_000, "{} half-steps", a.len());
    assert_eq!(a.len(), b.len(), "as many steps");
    if let Some(k) = (0..a.len()).find(|&k| a[k] != b[k]) {
        panic!("step {k}: coils at {:?}, STEP/DIR at {:?}", a[k], b[k]);
    }
    let cfg = MachineConfig::defaults(Machine::Drum);
    for axis in 0..2 {
        let t = on_coils.coil_track(axis);
        assert!(t.illegal.is_empty(), "{:?}", t.illegal);
        // No faster than the motor pulls out (the planner's rate, a
        // little jitter of the interrupt's entry aside).
        let fastest = t.steps.windows(2).map(|w| w[1].0 - w[0].0).min().unwrap();
        let rate = 16e6 / fastest as f64;
        assert!(
            rate <= f64::from(COIL_MAX_RATE) * 1.01,
            "axis {axis}: {rate:.0} half-steps/s"
        );
        // Released a quarter second ($1=250) after the machine stops (a
        // pen lift's 150 ms keeps them; the two lifts between patterns
        // do not), and at the end.
        assert!(!t.energised(), "axis {axis} still energised");
        let offs: Vec<u64> = t.power.iter().filter(|p| !p.1).map(|p| p.0).collect();
        assert!(offs.len() >= 2, "axis {axis} released {offs:?}");
        let moves = on_coils.coil_track(1 - axis);
        for off in offs {
            // The last half-step of either motor before the release.
            let last =
                |steps: &[(u64, i64)]| steps.iter().rev().find(|s| s.0 < off).map_or(0, |s| s.0);
            let ms = (off - last(&t.steps).max(last(&moves.steps))) as f64 / 16e3;
            assert!(
                ms >= f64::from(cfg.idle_delay_ms) && ms < f64::from(cfg.idle_delay_ms) + 20.0,
                "axis {axis}: released {ms:.1} ms after the machine stopped"
            );
        }
    }
    assert!(
        !on_coils.uart_text().contains("error"),
        "{}",
        log_tail(&on_coils)
    );
    assert_ram_budget(&on_coils);
}

/// Released after every move (`$1=0`) and energised again for the next:
/// back at the phase it left, so a hundred short moves there and back
/// (a dwell between: the machine stands) end where they began, the
/// decoder counting every half-step; a feed hold mid-move and its resume
/// lose none; the soft limits hold on coils as on drivers.
#[test]
fn coils_released_between_moves_and_held_mid_move_lose_no_half_step() {
    let mut sim = boot_machine();
    send(&mut sim, "$machine=drum");
    send(&mut sim, "$1=0");
    send(&mut sim, "G0 X20 Y20");
    send(&mut sim, "G91");
    for k in 0..100 {
        let d = if k % 2 == 0 { 0.3 } else { -0.3 };
        send(&mut sim, &format!("G1 X{d} Y{} F600", -d));
        send(&mut sim, "G4 P20");
    }
    send(&mut sim, "G90");
    send(&mut sim, "M400");
    sim.run_for(Duration::from_millis(50));
    let x = sim.coil_track(0);
    // 20 mm: 2048 half-steps of X.
    assert_eq!(x.position(), 2048, "{}", log_tail(&sim));
    let releases = x.power.iter().filter(|p| !p.1).count();
    assert!(releases >= 100, "released {releases} times");
    assert!(!x.energised());
    // A hold in the middle of a long move, then its resume.
    sim.uart_send(b"G0 X60\n");
    sim.run_for(Duration::from_millis(1500));
    sim.uart_send(b"!");
    sim.run_for(Duration::from_millis(1000));
    let held = sim.coil_track(0).position();
    assert!(held > 2048 && held < 6144, "held at {held}");
    sim.uart_send(b"~");
    send(&mut sim, "M400");
    sim.run_for(Duration::from_millis(50));
    assert_eq!(sim.coil_track(0).position(), 6144);
    // X's travel is 0…200 mm.
    match sim.send_line("G0 X250", Duration::from_secs(1)) {
        Ok(Reply::Error(_)) => {}
        other => panic!("G0 X250: {other:?}"),
    }
    sim.run_for(Duration::from_millis(300));
    assert_eq!(sim.coil_track(0).position(), 6144, "nothing moved");
    assert_ram_budget(&sim);
}

/// `$x_driver` per axis, listed in `$$`, kept in EEPROM across a power
/// cycle; a name it does not know is refused; switching an axis to coils
/// slows it to the 28BYJ-48's pull-out rate.
#[test]
fn the_driver_setting_is_listed_stored_and_checked() {
    let eeprom = {
        let mut sim = boot_machine();
        send(&mut sim, "$machine=drum");
        send(&mut sim, "$y_driver=stepdir");
        sim.run_for(Duration::from_secs(2));
        sim.eeprom()
    };
    let mut sim = hil_tests::machine();
    sim.set_eeprom(&eeprom);
    hil_tests::wait_for(&mut sim, "reset:", Duration::from_millis(100));
    let start = sim.uart_bytes().len();
    send(&mut sim, "$$");
    let list = sim.uart_text_from(start);
    for line in [
        "$x_driver=uln2003\n",
        "$y_driver=stepdir\n",
        "$z_driver=stepdir\n",
    ] {
        assert!(list.contains(line), "{line:?} in {list}");
    }
    // 4096 half-steps per 40 mm.
    assert!(list.contains("$100=102.400\n"), "{list}");
    match sim.send_line("$x_driver=a4988", Duration::from_secs(1)) {
        Ok(Reply::Error(_)) => {}
        other => panic!("{other:?}"),
    }
    send(&mut sim, "$machine=flatbed");
    send(&mut sim, "$x_driver=ULN2003");
    let start = sim.uart_bytes().len();
    send(&mut sim, "$$");
    let list = sim.uart_text_from(start);
    assert!(list.contains("$x_max_rate=1000\n"), "{list}");
    assert!(list.contains("$y_max_rate=2000\n"), "{list}");
}
