//! The machine's `error:N` and `ALARM:N` in plain words, with what to do
//! next: Grbl 1.1's numbers (its `doc/csv` tables) and taut's own, as the
//! page shows them beside the firmware's `[MSG:…]` line.

/// What `error:code` means and what to do about it.
pub fn error(code: u32) -> (&'static str, &'static str) {
    match code {
        1 => (
            "a word must start with a letter",
            "check the line for a stray character",
        ),
        2 => (
            "a number is missing or malformed",
            "check the line's numbers",
        ),
        3 => (
            "the $ command is not known or its value is refused",
            "see $$ for the settings' names and ranges",
        ),
        4 => ("a value may not be negative", "use a positive F or P"),
        5 => (
            "homing is not set up on this machine",
            "set homing_axes, or zero by hand",
        ),
        8 => (
            "the machine must stand still for that",
            "wait until it is Idle, or pause and stop",
        ),
        9 => (
            "the machine is locked: its position is unknown",
            "home it ($H) or unlock it ($X), then zero",
        ),
        11 => ("the line is longer than the machine takes", "split it"),
        15 => (
            "the target is outside the machine's travel",
            "make the drawing smaller or move it, or jog back inside",
        ),
        16 => (
            "the jog command is not valid",
            "a jog is $J= with G91 or G90, axis words and F",
        ),
        20 => (
            "the machine does not know that command",
            "leave it out of the file",
        ),
        21 => ("two commands of one group on a line", "one per line"),
        22 => ("no feed rate yet for G1/G2/G3", "add an F word"),
        24 | 25 | 26 | 27 | 28 | 31 | 36 => (
            "the line's words do not fit together",
            "check the line against the G-code it means",
        ),
        32 | 34 | 35 => (
            "the arc cannot be drawn as written",
            "check its centre or radius",
        ),
        33 => (
            "the target cannot be reached",
            "keep inside the machine's reach",
        ),
        60 => ("no card in the slot", "insert a FAT card"),
        61 => (
            "the card failed while reading",
            "take it out and put it back, or replace it",
        ),
        65 => ("no such file on the card", "list the card with M20"),
        67 => (
            "the machine prints from its card",
            "pause (M25) or abort (M524) the print first",
        ),
        70 => ("a checksum is wrong", "send the line again"),
        71 => (
            "a string-art job owns the machine",
            "wait for it, pause it, or stop it (Ctrl-X)",
        ),
        72 => ("the feed rate is too low", "use F10 or more"),
        73 => (
            "the pen (Z) and X/Y on one line",
            "put the pen move on its own line",
        ),
        75 => (
            "homing failed: no switch found, or one stuck",
            "check the switches, then $H again or $X",
        ),
        76 => ("no file selected", "select one with M23"),
        _ => ("the machine refused the line", "see the message before it"),
    }
}

/// What `ALARM:code` means and what to do about it.
pub fn alarm(code: u32) -> (&'static str, &'static str) {
    match code {
        1 => (
            "a limit switch closed while moving: the position is lost",
            "free the axis, then $X and home ($H)",
        ),
        2 => (
            "a move would have left the travel (soft limit)",
            "$X, then send moves inside the travel",
        ),
        3 => (
            "reset while moving: steps may have been lost",
            "unlock ($X) and zero or home again ($H)",
        ),
        4 | 5 => ("the probe did not behave", "check the probe, then $X"),
        6..=9 => (
            "homing failed",
            "check the switches and their wiring, then $H again",
        ),
        _ => (
            "the machine stopped with an alarm",
            "unlock it ($X) and home it ($H)",
        ),
    }
}

/// A reply line in plain words, if it is an error or an alarm.
pub fn explain(line: &str) -> Option<String> {
    let (what, code) = if let Some(c) = line.strip_prefix("error:") {
        ("error", c)
    } else {
        ("alarm", line.strip_prefix("ALARM:")?)
    };
    let code: u32 = code.trim().split(' ').next()?.parse().ok()?;
    let (means, next) = match what {
        "error" => error(code),
        _ => alarm(code),
    };
    Some(format!("{line}: {means}. What to do: {next}."))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_and_alarms_read_as_words_with_what_to_do() {
        assert_eq!(
            explain("error:9").unwrap(),
            "error:9: the machine is locked: its position is unknown. What to do: home it ($H) or unlock it ($X), then zero."
        );
        assert!(explain("ALARM:3").unwrap().contains("unlock ($X)"));
        assert!(explain("error:999").unwrap().contains("see the message"));
        assert_eq!(explain("ok"), None);
        assert_eq!(explain("error:x"), None);
    }
}
