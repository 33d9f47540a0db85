use super::*;

#[test]
fn comments_blanks_and_spaces_stay_home_and_lines_keep_their_numbers() {
    let text = b"; a drawing\nG21\n\n G1 X1 ; out\n%\n(setup)\nG0 X2 (a; b) Y3\r\nM5 (open\n\t$machine = flatbed ; $ text\n$J=G91 X1 F100\n";
    let lines = lines_of(text);
    let want = [
        (2, "G21"),
        (4, "G1X1"),
        (7, "G0X2Y3"),
        (8, "M5"),
        (9, "$machine = flatbed"),
        (10, "$J=G91X1F100"),
    ];
    let want: Vec<(usize, String)> = want.iter().map(|(n, l)| (*n, l.to_string())).collect();
    assert_eq!(lines, want);
}

#[test]
fn the_window_holds_what_grbl_s_buffer_holds_and_frees_in_order() {
    let mut w = Window::default();
    let line = "G1 X10.000 Y20.000"; // 19 bytes with its newline
    let mut sent = 0;
    while w.fits(line) {
        w.sent(sent, line);
        sent += 1;
    }
    assert_eq!(sent, 128 / 19);
    assert!(w.bytes < RX_BUFFER && w.bytes + 19 >= RX_BUFFER);
    assert_eq!(w.answered(), Some(0));
    assert!(w.fits(line), "an ok frees a line's room");
    assert_eq!(w.answered(), Some(1));
    // The longest line fits an empty window only.
    let mut w = Window::default();
    let long = "X".repeat(126);
    assert!(w.fits(&long));
    w.sent(0, "G0");
    assert!(!w.fits(&long));
    assert_eq!(w.answered(), Some(0));
    assert_eq!(w.answered(), None, "no reply without a line");
}

#[test]
fn the_eta_grows_line_by_line_to_the_total() {
    let lines = lines_of(b"G21 G90\nG1 X10 F600\nG4 P500\nG1 X20\n");
    let eta = Eta::of(&lines, &MachineConfig::defaults(Machine::Flatbed));
    assert!(
        eta.after.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        eta.after
    );
    assert!(
        eta.total > 2.0 && eta.total >= eta.after[3],
        "{}",
        eta.total
    );
}

/// `$$` as the firmware lists it (Grbl's numbered settings, then the
/// named ones) gives back the configuration it was listed from.
#[test]
fn the_listing_gives_the_machine_s_figures() {
    struct Line(String);
    impl ufmt::uWrite for Line {
        type Error = std::convert::Infallible;
        fn write_str(&mut self, s: &str) -> Result<(), Self::Error> {
            self.0.push_str(s);
            Ok(())
        }
    }
    let mut cfg = MachineConfig::defaults(Machine::Flatbed);
    settings::set(&mut cfg, "x_max_rate", "3100").unwrap();
    settings::set(&mut cfg, "y_accel", "1234").unwrap();
    settings::set(&mut cfg, "homing_at_start", "0").unwrap();
    assert_ne!(cfg, MachineConfig::defaults(Machine::Flatbed));
    let mut listing = vec!["[MSG:a note]".to_string()];
    for i in 0.. {
        let Some(listed) = settings::listed(i, &cfg, &Default::default()) else {
            break;
        };
        let mut line = Line(String::new());
        ufmt::uwrite!(line, "{}", listed).unwrap();
        listing.push(line.0);
    }
    assert!(
        listing.iter().any(|l| l.starts_with("$110=")),
        "{listing:?}"
    );
    assert_eq!(config_of(&listing), Some(("flatbed".to_string(), cfg)));
    // Not taut's (no $machine): no figures.
    assert_eq!(config_of(&["$110=500.000".to_string()]), None);
}

#[test]
fn clock_reads_as_minutes_or_hours() {
    assert_eq!(clock(0.0), "0:00.0");
    assert_eq!(clock(65.34), "1:05.3");
    assert_eq!(clock(3725.0), "1:02:05");
}
