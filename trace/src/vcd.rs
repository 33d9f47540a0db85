//! Value Change Dump of one-bit signals: written from probe edges (GTKWave and
//! Surfer open it) and read back, by tests and by tools that rebuild motion
//! from the pulses.

use std::collections::HashMap;
use std::fmt::Write as _;

/// A one-bit signal: its level at time 0 and each later change, in ns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Signal {
    pub name: String,
    pub initial: bool,
    pub changes: Vec<(u64, bool)>,
}

/// VCD text (timescale 1 ns) holding `signals` under the scope `taut`.
pub fn render(signals: &[Signal]) -> String {
    let ids: Vec<String> = (0..signals.len()).map(identifier).collect();
    let mut out = String::from("$timescale 1ns $end\n$scope module taut $end\n");
    for (s, id) in signals.iter().zip(&ids) {
        // VCD names are single tokens.
        let name: String = s
            .name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        let _ = writeln!(out, "$var wire 1 {id} {name} $end");
    }
    out.push_str("$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n");
    for (s, id) in signals.iter().zip(&ids) {
        let _ = writeln!(out, "{}{id}", u8::from(s.initial));
    }
    out.push_str("$end\n");
    let mut changes: Vec<(u64, usize, bool)> = signals
        .iter()
        .enumerate()
        .flat_map(|(i, s)| s.changes.iter().map(move |&(t, v)| (t, i, v)))
        .collect();
    changes.sort_by_key(|&(t, i, _)| (t, i));
    let mut now = None;
    for (t, i, v) in changes {
        if now != Some(t) {
            let _ = writeln!(out, "#{t}");
            now = Some(t);
        }
        let _ = writeln!(out, "{}{}", u8::from(v), ids[i]);
    }
    out
}

/// Short printable identifier for the n-th signal (base 94 over `!`..`~`).
fn identifier(mut n: usize) -> String {
    let mut id = String::new();
    loop {
        id.push((b'!' + (n % 94) as u8) as char);
        n /= 94;
        if n == 0 {
            return id;
        }
        n -= 1;
    }
}

/// Reads the one-bit signals of a VCD, times converted to ns. Values `x`/`z`
/// read as low; vector signals are skipped.
pub fn parse(text: &str) -> Result<Vec<Signal>, String> {
    let mut tokens = text.split_whitespace();
    let mut signals: Vec<Signal> = Vec::new();
    let mut by_id: HashMap<String, usize> = HashMap::new();
    let mut seen = Vec::new();
    let mut ns_per_tick = 1u64;
    let mut now = 0u64;
    let mut in_dumpvars = false;
    while let Some(tok) = tokens.next() {
        match tok {
            "$timescale" => {
                let spec: String = tokens
                    .by_ref()
                    .take_while(|t| *t != "$end")
                    .collect::<Vec<_>>()
                    .concat();
                ns_per_tick = timescale_ns(&spec)?;
            }
            "$var" => {
                let fields: Vec<&str> = tokens.by_ref().take_while(|t| *t != "$end").collect();
                if let [_kind, "1", id, name, ..] = fields[..] {
                    by_id.insert(id.to_owned(), signals.len());
                    signals.push(Signal {
                        name: name.to_owned(),
                        initial: false,
                        changes: Vec::new(),
                    });
                    seen.push(false);
                }
            }
            "$dumpvars" => in_dumpvars = true,
            "$end" => in_dumpvars = false,
            t if t.starts_with('$') => {
                // Skip the body of any other section.
                tokens.by_ref().find(|t| *t == "$end");
            }
            t if t.starts_with('#') => {
                let ticks: u64 = t[1..].parse().map_err(|_| format!("bad time {t}"))?;
                now = ticks * ns_per_tick;
            }
            t if t.starts_with(['b', 'B', 'r', 'R']) => {
                tokens.next(); // vector value: its identifier follows
            }
            t => {
                let (value, id) = t.split_at(1);
                let Some(&i) = by_id.get(id) else { continue };
                let high = match value {
                    "1" => true,
                    "0" | "x" | "X" | "z" | "Z" => false,
                    _ => return Err(format!("bad value change {t}")),
                };
                let s = &mut signals[i];
                if in_dumpvars || (!seen[i] && now == 0) {
                    s.initial = high;
                } else if s.changes.last().map_or(s.initial, |c| c.1) != high {
                    s.changes.push((now, high));
                }
                seen[i] = true;
            }
        }
    }
    Ok(signals)
}

/// Nanoseconds per tick of a `$timescale` such as `1ns`, `10 us`, `1ps` (only
/// whole nanoseconds are supported).
fn timescale_ns(spec: &str) -> Result<u64, String> {
    let digits = spec
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(spec.len());
    let n: u64 = spec[..digits]
        .parse()
        .map_err(|_| format!("bad timescale {spec}"))?;
    let unit = match &spec[digits..] {
        "ns" => 1,
        "us" => 1_000,
        "ms" => 1_000_000,
        "s" => 1_000_000_000,
        _ => return Err(format!("unsupported timescale {spec}")),
    };
    Ok(n * unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_then_parse_round_trips() {
        let signals = vec![
            Signal {
                name: "x step".into(),
                initial: false,
                changes: vec![(62, true), (187, false), (1_000, true)],
            },
            Signal {
                name: "x_dir".into(),
                initial: true,
                changes: vec![(187, false)],
            },
        ];
        let text = render(&signals);
        assert!(text.contains("$timescale 1ns $end"));
        let back = parse(&text).unwrap();
        assert_eq!(back[0].name, "x_step");
        assert_eq!(back[0].changes, signals[0].changes);
        assert_eq!(back[1], signals[1]);
    }

    #[test]
    fn identifiers_are_distinct() {
        let ids: std::collections::HashSet<String> = (0..10_000).map(identifier).collect();
        assert_eq!(ids.len(), 10_000);
    }

    #[test]
    fn parses_foreign_timescale_and_skips_vectors() {
        let text = "$date today $end $timescale 10 us $end $scope module m $end \
                    $var wire 8 # bus $end $var wire 1 ! led $end $upscope $end \
                    $enddefinitions $end #0 0! b1010 # #3 1! #5 1! #7 0!";
        let s = parse(text).unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].changes, vec![(30_000, true), (70_000, false)]);
    }
}
