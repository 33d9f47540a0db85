//! `docs/benchmarks.md`, written by `cargo xtask bench` from
//! `target/bench.json`: the method, then every figure with its unit, what
//! it measures and its bar where one exists. The README and the other
//! pages cite figures from this page only, so none goes stale in prose.

use serde_json::{Map, Value};

/// A bar a figure must meet.
#[derive(Clone, Copy)]
enum Bar {
    AtMost(f64),
    AtLeast(f64),
}

impl Bar {
    fn met(self, v: f64) -> bool {
        match self {
            Bar::AtMost(b) => v <= b,
            Bar::AtLeast(b) => v >= b,
        }
    }

    fn text(self) -> String {
        match self {
            Bar::AtMost(b) => format!("≤ {}", number(b)),
            Bar::AtLeast(b) => format!("≥ {}", number(b)),
        }
    }
}

/// A figure of `target/bench.json`: its key, unit, what it measures, bar.
struct Figure {
    key: &'static str,
    unit: &'static str,
    what: &'static str,
    bar: Option<Bar>,
}

const fn fig(key: &'static str, unit: &'static str, what: &'static str) -> Figure {
    Figure {
        key,
        unit,
        what,
        bar: None,
    }
}

const fn barred(key: &'static str, unit: &'static str, what: &'static str, bar: Bar) -> Figure {
    Figure {
        key,
        unit,
        what,
        bar: Some(bar),
    }
}

/// The flash the firmware may use: the bootloader owns the top.
pub const FLASH_BUDGET: f64 = crate::firmware::FLASH_BUDGET as f64;
/// Static RAM plus the deepest stack.
pub const RAM_BUDGET: f64 = crate::firmware::RAM_BUDGET as f64;

/// The sections of the page, in order, with their figures.
const SECTIONS: &[(&str, &[Figure])] = &[
    (
        "Size",
        &[
            barred("flash_bytes", "B", "flash of the release image (`.text` + `.data`)", Bar::AtMost(FLASH_BUDGET)),
            fig("ram_static_bytes", "B", "static RAM (`.data` + `.bss` + `.noinit`)"),
            fig("data_bytes", "B", "`.data`, the part of static RAM that is also in flash"),
            fig("stack_peak_bytes", "B", "deepest stack of the bench's runs (the cruise, the loaded console); `cargo xtask test` prints the HIL run's deepest"),
            barred("ram_static_plus_stack_bytes", "B", "static RAM + `stack_peak_bytes`", Bar::AtMost(RAM_BUDGET)),
        ],
    ),
    (
        "Step timing",
        &[
            fig("step_rate_1axis_hz", "steps/s", "highest one-axis cruise rate (to 1 kHz) at which every pulse of a 1 s cruise lands within 2 µs of a uniform grid"),
            barred("step_rate_1axis_error_us", "µs", "worst pulse deviation from that grid at that rate", Bar::AtMost(2.0)),
            fig("step_rate_1axis_rate_error_ppm", "ppm", "that grid's rate against the nominal rate (a crystal is good to ±50 ppm)"),
            fig("isr_cycles_per_step", "cycles", "the step interrupt's mean cycles per event, one axis"),
            fig("step_rate_3axis_hz", "steps/s", "as `step_rate_1axis_hz`, three axes stepping at every event (aggregate: 3 × the event rate)"),
            barred("step_rate_3axis_error_us", "µs", "worst pulse deviation at that rate", Bar::AtMost(2.0)),
            fig("step_rate_3axis_rate_error_ppm", "ppm", "that grid's rate against the nominal rate"),
            fig("isr_cycles_per_event_3axis", "cycles", "the step interrupt's mean cycles per event, three axes"),
            fig("timing_error_max_us", "µs", "a default-speed `G0 C360` (2000 steps/s, 500 steps/s²): worst pulse against the exact trapezoid"),
            barred("step_isr_max_masked_cycles", "cycles", "longest stretch with the step interrupt masked during that move", Bar::AtMost(80.0)),
        ],
    ),
    (
        "Latency under load",
        &[
            fig("status_latency_cycles", "cycles", "`?` received (its receive interrupt) → the `Realtime` task starts, worst"),
            fig("status_latency_p90_cycles", "cycles", "the same, 90th percentile"),
            barred("status_report_latency_us", "µs", "`?` received → the status report's last byte queued, worst (a `?` every 25 ms)", Bar::AtMost(10_000.0)),
            fig("status_report_latency_p90_us", "µs", "the same, 90th percentile"),
            fig("dispatch_latency_cycles", "cycles", "a line's byte received → the `Console` task starts, worst"),
            fig("dispatch_latency_p90_cycles", "cycles", "the same, 90th percentile"),
            fig("segment_prep_max_cycles", "cycles", "segment preparation's longest run during the demo job"),
        ],
    ),
    (
        "Streaming",
        &[
            fig("stream_lines_per_s", "lines/s", "1 mm moves at the maximum feed streamed by character counting (Grbl's 128 bytes), answered per second"),
            fig("stream_uart_bound_lines_per_s", "lines/s", "what 115 200 baud could carry of those lines"),
            fig("stream_estimate_lines_per_s", "lines/s", "the host estimate of the same stream (the firmware's planner on the host)"),
            fig("stream_planner_free_blocks_mean", "blocks", "mean free planner blocks in the stream's `?` reports (`Bf:`)"),
            fig("stream_lines_always_waiting", "", "whether a whole line always waited in the receive buffer"),
            fig("stream_limit", "", "what limits the stream: the planner, the UART or the firmware's line intake"),
        ],
    ),
    (
        "Look-ahead",
        &[
            fig("planner_blocks", "blocks", "moves the planner holds (`PLANNER_BLOCKS`: what the RAM budget leaves)"),
            fig("fine_curve_top_feed_mm_per_min", "mm/min", "the fine curve's feed: 2 000 pieces of 0.1 mm along an arc of R 150 mm on the flatbed, asked at its top feed"),
            fig("fine_curve_host_feed_mm_per_min", "mm/min", "the curve's mean feed on the host: the same lines through the firmware's parser, executor and planner at its depth (no CPU or UART limit)"),
            fig("fine_curve_host_36_feed_mm_per_min", "mm/min", "the same with Grbl-Mega's 36 blocks of look-ahead"),
            fig("fine_curve_feed_mm_per_min", "mm/min", "the firmware's mean feed, first step to last, the lines streamed by character counting (Grbl's 128 bytes)"),
            barred("fine_curve_feed_ratio", "", "the firmware's mean feed over the host's at its depth", Bar::AtLeast(0.95)),
            barred("fine_curve_underruns", "", "step-queue underruns the firmware counted meanwhile", Bar::AtMost(0.0)),
        ],
    ),
    (
        "Maths on the AVR",
        &[
            fig("polargraph_inverse_cycles", "cycles", "one whiteboard (polargraph) inverse kinematics (`fmath`)"),
            fig("scara_inverse_cycles", "cycles", "one SCARA inverse kinematics"),
            fig("arc_segments_per_s", "chords/s", "chords of a 1 mm circle cut, converted and planned on the flatbed"),
            fig("isqrt64_cycles", "cycles", "one 64-bit integer square root"),
            fig("trapezoid_new_cycles", "cycles", "one trapezoid made (`Trapezoid::new`)"),
            fig("trapezoid_time_cycles", "cycles", "one event time read off a trapezoid"),
            fig("segment_cycles_mean", "cycles", "one segment of a default-speed move cut, mean"),
            fig("segments_per_default_move", "segments", "segments of that move"),
        ],
    ),
    (
        "Feed along the pen",
        &[
            barred("feed_ratio_scara_min", "", "the arm's fixed lines (`SCARA_LINES` in `simavr/src/bin/taut-bench/main.rs`: 40 mm at F600 in two places, 120 mm at F1500 and F3000): time from first to last step over the pen's trapezoid (length at the feed, ramps at `pen_accel`), lowest; below 1 would be faster than asked", Bar::AtLeast(0.97)),
            fig("feed_ratio_scara_max", "", "the same, highest: above 1 where a joint's own limits hold the pen back"),
            barred("feed_ratio_whiteboard_min", "", "the whiteboard's (`WHITEBOARD_LINES`: 40 mm at F600, three of 410–500 mm at F900–F3000 across the board), lowest", Bar::AtLeast(0.97)),
            fig("feed_ratio_whiteboard_max", "", "the same, highest"),
        ],
    ),
    (
        "Card",
        &[
            fig("sd_read_kib_per_s", "KiB/s", "a 256 KiB file streamed through the card reader into its queue (`firmware/examples/sd_read.rs`)"),
            fig("sd_poradi_parse_ms", "ms", "reading and checking a card with a 3 000-connection `poradi.txt`, `state: reading` → `files ok`, by the firmware's clock"),
        ],
    ),
    (
        "The string-art job",
        &[
            fig("cpu_busy_percent_drilling", "%", "share of cycles the MCU is awake while the demo job drills"),
            fig("cpu_busy_percent_winding", "%", "the same, its first 30 s of winding"),
            fig("job_time_s", "s", "the demo card's machine time (host, the firmware's own job, planner and trapezoids)"),
            fig("job_time_sequential_s", "s", "the same card with the original firmware's blocking moves, one axis after another"),
            barred("job_time_ratio", "", "`job_time_s` / `job_time_sequential_s`", Bar::AtMost(0.70)),
            fig("job_250x3000_time_s", "s", "the seed's example size: 250 nails on a 40.2 cm circle, 3 000 connections"),
            fig("job_250x3000_time_sequential_s", "s", "the same, one axis after another"),
            fig("job_250x3000_time_ratio", "", "their ratio"),
            fig("eeprom_writes_per_job", "B", "EEPROM bytes the checkpoint writes in a 250-hole, 3 000-wrap job"),
            fig("eeprom_cell_writes_per_job", "writes", "writes of the most written EEPROM cell in that job"),
            fig("jobs_before_wear_out", "jobs", "such jobs before that cell reaches the datasheet's 100 000 writes"),
            fig("resume_prompt_ms", "ms", "simulated time from power-on to the `>>> resume …` prompt after a cut while winding"),
        ],
    ),
    (
        "The simulator",
        &[
            barred("sim_mhz", "MHz", "simulated MHz per wall second, the demo job run whole as `cargo xtask demo` runs it", Bar::AtLeast(750.0)),
            barred("demo_wall_s", "s", "wall seconds that took", Bar::AtMost(15.0)),
            fig("sim_mhz_idle", "MHz", "simulated MHz per wall second, the firmware idle"),
            fig("sim_mhz_busy", "MHz", "the same, an MCU that never sleeps (`firmware/examples/busy.rs`)"),
            fig("host_cores", "cores", "the host's cores the bench ran on"),
            fig("host_load_average", "", "the host's 1-minute load average when the bench started: the wall-clock figures shrink as it grows"),
        ],
    ),
];

const METHOD: &str = "\
Every figure is measured by `cargo xtask bench` and written to
`target/bench.json`; this page is generated from that file by the same
command (`xtask/src/bench_page.rs`). Do not edit it by hand: run the bench
and commit the page.

- **Firmware figures** come from the release image (`taut.elf`, the one
  that is flashed) in simavr, whose cycle counter is exact and repeatable
  (`simavr/src/bin/taut-bench/main.rs`). Special images in `firmware/examples/`
  time the maths (`kin_cycles`, `segment_cycles`), the card reader
  (`sd_read`) and an MCU that never sleeps (`busy`).
- **Step rates** are searched to 1 kHz: the highest cruise rate at which
  every STEP pulse of a one-second cruise lands within 2 µs of a uniform
  grid fitted to it. The search is not monotonic (a rate fails when a step
  falls on another interrupt's masked entry), so the rate moves by a few
  thousand from build to build as the code's layout moves.
- **Latencies** are measured under load: the console streams 0.1 mm moves
  at the maximum feed (the planner full, a segment to cut every few ms)
  while the job reads the sample card, and a byte arrives every 5 ms (a `?`
  every 25 ms for the report).
- **Streams of short segments** (`taut-bench --stream FIRMWARE_ELF
  [name part]` alone, in `simavr/src/bin/taut-bench/stream.rs`): a circle
  (R 20 mm; 10 mm on the arm) cut into 1 200 chords of 0.05 mm or 400 of
  0.2 mm at F1500, absolute coordinates to the µm, sent over the serial
  port by character counting (lines per second answered from the first
  tenth to the last) or printed from the card (`M24` answered → `Done
  printing file`). Underruns are the firmware's own count (its logger's
  `underruns:N`) over the stream. Beside each, what the planner allows
  at the firmware's depth and at Grbl-Mega's 36 blocks, however fast the
  CPU and the line (the host's time of the stream cut after its last
  tenth less that of the stream cut after its first, each run out to a
  stop): short moves at speed are bound by the look-ahead (the machine
  must be able to stop within the planned blocks) and by the junctions,
  which Grbl's rule takes between the moves as rounded to steps. taut
  joins a circle's tiny chords into moves of about a millimetre within
  the arc tolerance (`docs/console.md`), so its planner allows the feed
  itself (F1500: 500 chords of 0.05 mm a second); Grbl-Mega plans each
  chord (a 0.05 mm chord is two steps of the flatbed's 0.025 mm, so the
  direction turns by tens of degrees from one to the next).
  The simulated line carries a byte every 11 bits of the rate the
  firmware set (UBRR0 16 with U2X0: 117 647 baud, 10.7 kB/s), simavr's
  receiver; the flatbed's 0.05 mm chords (19 bytes a line) come at most
  some 560 a second over serial. (simavr works out a USART's byte time
  only when UBRRnL is written; the simulator works it out again when U2X
  is set after, as the firmware does, and the silicon does not mind.)
  `TAUT_BENCH_PROFILE=N` prints where a case's cycles go: per function,
  with callees (a shadow call stack), the callers of the maths library.
- **Grbl side by side** (`grbl_stream_*`, `simavr/src/bin/taut-bench/grbl.rs`):
  with `TAUT_GRBL_MEGA` naming a grbl-Mega checkout (outside this
  repository), the bench builds it with `avr-gcc` as its Makefile does
  (its RAMPS/Mega defaults), sets its `$100`–`$121` and `$11` to the
  flatbed's steps, rates, accelerations and junction deviation, and
  streams the flatbed's circles by the same character counting in the
  same simulator: what a 16 MHz AVR running Grbl carries of the same
  lines. simavr starts no CTC timer whose TOP is 0, so the bench gives
  Grbl's Timer1 compare register its top before boot (Grbl sets it at
  its stepper interrupt's first run); the first move starts ≤ 4.1 ms late.
- **The fine curve** (`taut-bench --curve FIRMWARE_ELF` alone, in
  `simavr/src/bin/taut-bench/curve.rs`): 2 000 pieces of 0.1 mm along an
  arc of R 150 mm on the flatbed (0.04° a piece; to the µm, so each
  piece's 4 steps turn its direction by up to 14°), asked at the
  flatbed's top feed and streamed by character counting; the mean feed is
  the path's length over the time from its first step to its last.
  Beside it the same lines on the host through the firmware's parser,
  executor and planner (`GcodeTime`, the planner's depth a parameter of
  the same code): at the firmware's depth and at Grbl-Mega's 36 blocks.
  The two host figures agree when the speed is set by the acceleration
  and the junctions, not by how far the planner looks ahead.
- **Feed ratios** (`taut-bench --feed FIRMWARE_ELF` alone): fixed lines
  drawn on the whiteboard and the arm, each line's time from its first
  step to its last over its trapezoid along the pen; `F` is the pen's
  speed, so 1 is the feed kept (a hair under: the first step comes a
  fraction of a step's travel after the start).
- **Machine times** of the string-art job are worked out on the host with
  the firmware's own job state machine, planner and trapezoids (`cargo
  xtask estimate`), which the HIL job test holds to the simulation within
  1 %.
- **Host string art** (`cargo taut bench`): a 250-nail circle of R 40.2 cm,
  3 000 lines of 0.3 mm thread, 512 px, on the test images in
  `examples/images/`: ours, the plain greedy chord choice and random
  chords; RMSE of darkness (0–1) after a σ = 2 px blur of both. Wall
  seconds depend on the machine and its load.
- **Wall-clock figures** (`sim_mhz*`, `demo_wall_s`, `stringart_seconds_*`)
  depend on the machine and what else runs on it.
- **Bars** are the project's rules: flash ≤ 224 KiB (229 376 B; the
  bootloader owns the top); static RAM + deepest stack ≤ 5.5 KiB (5 632 B;
  `cargo xtask test` checks every HIL test's stack against it and prints
  the deepest); every pulse within 2 µs; the step interrupt masked at most
  80 cycles (5 µs); a `?` answered within 10 ms; the demo card in at most
  70 % of the original firmware's time; the simulator at least 750 MHz and
  the demo job in at most 15 s of wall time; our string art at least 25 %
  below random chords' error and below the plain greedy's.

For comparison: Grbl steps at more than 30 kHz, Marlin on the Mega at about
40 kHz, Klipper on a 16 MHz AVR at about 99 k steps/s on three steppers.
";

/// The page for `figures` (`target/bench.json`), and the bars missed.
pub fn render(figures: &Map<String, Value>) -> (String, Vec<String>) {
    let mut out = String::from("# Benchmarks\n\n");
    out += METHOD;
    let mut missed = Vec::new();
    let mut shown = std::collections::BTreeSet::new();
    for (title, figs) in SECTIONS {
        let mut rows: Vec<Row> = figs
            .iter()
            .filter_map(|f| {
                row(
                    figures,
                    &mut shown,
                    f.key.into(),
                    f.unit,
                    f.what.into(),
                    f.bar,
                )
            })
            .collect();
        if *title == "Streaming" {
            rows.extend(stream_case_rows(figures, &mut shown));
        }
        table(&mut out, title, &rows, &mut missed);
    }
    let stringart = stringart_rows(figures, &mut shown);
    table(&mut out, "Host string art", &stringart, &mut missed);
    let other: Vec<Row> = figures
        .iter()
        .filter(|(k, _)| !shown.contains(*k))
        .map(|(k, v)| Row {
            key: k.clone(),
            value: v.clone(),
            unit: String::new(),
            what: "(not described yet: add it to `xtask/src/bench_page.rs`)".into(),
            bar: None,
        })
        .collect();
    table(&mut out, "Other", &other, &mut missed);
    (out, missed)
}

struct Row {
    key: String,
    value: Value,
    unit: String,
    what: String,
    /// The bar's text and whether it is met.
    bar: Option<(String, bool)>,
}

/// The row of figure `key`, if the bench measured it.
fn row(
    figures: &Map<String, Value>,
    shown: &mut std::collections::BTreeSet<String>,
    key: String,
    unit: &str,
    what: String,
    bar: Option<Bar>,
) -> Option<Row> {
    let v = figures.get(&key)?;
    shown.insert(key.clone());
    Some(Row {
        bar: bar.map(|b| (b.text(), v.as_f64().is_some_and(|x| b.met(x)))),
        key,
        value: v.clone(),
        unit: unit.into(),
        what,
    })
}

/// The stream cases (`simavr/src/bin/taut-bench/stream.rs`): for each
/// machine and chord length, what its planner allows, then serial and
/// card, each with its underruns; then Grbl-Mega's figures beside them.
fn stream_case_rows(
    figures: &Map<String, Value>,
    shown: &mut std::collections::BTreeSet<String>,
) -> Vec<Row> {
    const UNDERRUNS: &str =
        "step-queue underruns the firmware counted meanwhile (the queue dry inside a planned move)";
    let mut rows = Vec::new();
    for (machine, name, serial_bar, card_bar) in [
        ("flatbed", "flatbed", 300.0, 450.0),
        ("whiteboard", "whiteboard", 200.0, 200.0),
        ("scara", "SCARA arm", 200.0, 200.0),
    ] {
        for (size, mm, short) in [("50um", "0.05", true), ("200um", "0.2", false)] {
            // Chords of 0.2 mm at F1500 come at most 125 a second.
            let (at_most, bar): (&str, fn(f64) -> Option<Bar>) = match short {
                true => ("", |b| Some(Bar::AtLeast(b))),
                false => (" (at most 125 at that feed)", |_| None),
            };
            let key = |what: &str| format!("stream_{machine}_{size}_{what}");
            let cases = [
                (key("planner_bound_lines_per_s"), "lines/s", format!("{mm} mm chords of a circle at F1500 on the {name}: what its planner allows (the same lines through the firmware's parser, executor and planner on the host, no CPU or UART limit)"), None),
                (key("planner_36_bound_lines_per_s"), "lines/s", "the same with Grbl-Mega's 36 blocks of look-ahead".into(), None),
                (key("serial_lines_per_s"), "lines/s", format!("the same over serial by character counting (Grbl's 128 bytes), lines carried out per second{at_most}"), bar(serial_bar)),
                (key("serial_underruns"), "", UNDERRUNS.into(), Some(Bar::AtMost(0.0))),
                (key("card_lines_per_s"), "lines/s", format!("the same printed from the card, lines carried out per second{at_most}"), bar(card_bar)),
                (key("card_underruns"), "", UNDERRUNS.into(), Some(Bar::AtMost(0.0))),
            ];
            for (key, unit, what, bar) in cases {
                rows.extend(row(figures, shown, key, unit, what, bar));
            }
        }
    }
    let grbl = [
        ("50um", "grbl-Mega 1.1 (built from `TAUT_GRBL_MEGA`, its steps, rates, accelerations and junction deviation set to the flatbed's) in the same simulator: the flatbed's 0.05 mm stream over serial by the same character counting"),
        ("200um", "the same with the 0.2 mm stream"),
    ];
    for (size, what) in grbl {
        let key = format!("grbl_stream_{size}_serial_lines_per_s");
        rows.extend(row(figures, shown, key, "lines/s", what.into(), None));
    }
    rows
}

fn table(out: &mut String, title: &str, rows: &[Row], missed: &mut Vec<String>) {
    if rows.is_empty() {
        return;
    }
    *out += &format!("\n## {title}\n\n| figure | value | unit | what it measures | bar |\n| --- | ---: | --- | --- | --- |\n");
    for r in rows {
        let bar = match &r.bar {
            None => String::new(),
            Some((text, true)) => format!("{text} (met)"),
            Some((text, false)) => {
                missed.push(format!("{} = {} (bar {text})", r.key, value(&r.value)));
                format!("{text} (**missed**)")
            }
        };
        *out += &format!(
            "| `{}` | {} | {} | {} | {} |\n",
            r.key,
            value(&r.value),
            r.unit,
            r.what,
            bar
        );
    }
}

/// The host string-art figures, per image (`stringart_<figure>_<image>`):
/// ours, the plain greedy's and random chords', with their bars.
fn stringart_rows(
    figures: &Map<String, Value>,
    shown: &mut std::collections::BTreeSet<String>,
) -> Vec<Row> {
    let images: Vec<String> = figures
        .keys()
        .filter_map(|k| k.strip_prefix("stringart_rmse_random_"))
        .map(String::from)
        .collect();
    let mut rows = Vec::new();
    for image in &images {
        let get = |k: &str| figures.get(&format!("stringart_{k}_{image}"));
        let random = get("rmse_random").and_then(Value::as_f64);
        let plain = get("rmse_plain").and_then(Value::as_f64);
        let kinds: [(&str, &str, String); 7] = [
            ("rmse", "", format!("RMSE of our generator on `{image}`")),
            ("seconds", "s", "its wall seconds".into()),
            ("thread_m", "m", "its thread length".into()),
            (
                "rmse_plain",
                "",
                "RMSE of the plain greedy chord choice".into(),
            ),
            ("seconds_plain", "s", "its wall seconds".into()),
            ("thread_m_plain", "m", "its thread length".into()),
            ("rmse_random", "", "RMSE of random chords".into()),
        ];
        for (kind, unit, what) in kinds {
            let key = format!("stringart_{kind}_{image}");
            let Some(v) = figures.get(&key) else { continue };
            shown.insert(key.clone());
            let bar = match (kind, v.as_f64(), random, plain) {
                ("rmse", Some(x), Some(r), Some(p)) => Some((
                    format!(
                        "≤ 0.75 × random ({}), < plain",
                        number((7500.0 * r).round() / 1e4)
                    ),
                    x <= 0.75 * r && x < p,
                )),
                _ => None,
            };
            rows.push(Row {
                key,
                value: v.clone(),
                unit: unit.into(),
                what,
                bar,
            });
        }
    }
    rows
}

fn value(v: &Value) -> String {
    match v {
        Value::Number(n) => number(n.as_f64().unwrap_or(f64::NAN)),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// `x` with its integer digits grouped by three (`229 376`), as the docs
/// write figures.
fn number(x: f64) -> String {
    let text = format!("{x}");
    let (int, frac) = text.split_once('.').unwrap_or((&text, ""));
    let (sign, digits) = int.strip_prefix('-').map_or(("", int), |d| ("-", d));
    let mut grouped = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 && digits.len() > 4 {
            grouped.push(' ');
        }
        grouped.push(c);
    }
    match frac {
        "" => format!("{sign}{grouped}"),
        f => format!("{sign}{grouped}.{f}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn numbers_are_grouped_as_the_docs_write_them() {
        assert_eq!(number(229_376.0), "229 376");
        assert_eq!(number(4_480.0), "4480");
        assert_eq!(number(1_234_567.5), "1 234 567.5");
        assert_eq!(number(-12_345.0), "-12 345");
        assert_eq!(number(0.645), "0.645");
    }

    #[test]
    fn every_figure_is_shown_with_its_bar_and_a_missed_bar_is_named() {
        let figures = json!({
            "flash_bytes": 300_000,
            "ram_static_bytes": 3844,
            "sim_mhz": 1600.5,
            "stringart_rmse_camera": 0.11,
            "stringart_rmse_plain_camera": 0.23,
            "stringart_rmse_random_camera": 0.32,
            "something_new": 7,
        });
        let (page, missed) = render(figures.as_object().unwrap());
        assert!(page.contains("| `flash_bytes` | 300 000 | B |"), "{page}");
        assert!(page.contains("≤ 229 376 (**missed**)"), "{page}");
        assert!(page.contains("| `sim_mhz` | 1600.5 | MHz |"), "{page}");
        assert!(page.contains("≥ 750 (met)"), "{page}");
        assert!(page.contains("`stringart_rmse_camera` | 0.11 |"), "{page}");
        assert!(page.contains("< plain (met)"), "{page}");
        assert!(page.contains("| `something_new` | 7 |"), "{page}");
        assert_eq!(missed, ["flash_bytes = 300 000 (bar ≤ 229 376)"]);
    }
}
