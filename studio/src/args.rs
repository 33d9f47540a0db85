//! The command line of one `taut` command: positional words, `--name
//! value` (or `--name=value`, `-o value`) options and `--flag`s. Every
//! option must be taken by the command: anything left over is an error.

use std::str::FromStr;

pub struct Args {
    positional: Vec<String>,
    options: Vec<(String, Option<String>)>,
}

impl Args {
    /// `flags` are the options that take no value.
    pub fn parse(raw: &[String], flags: &[&str]) -> Result<Args, String> {
        let mut args = Args {
            positional: Vec::new(),
            options: Vec::new(),
        };
        let mut it = raw.iter();
        while let Some(word) = it.next() {
            let name = match word.strip_prefix("--") {
                Some(name) => name,
                None => match word.as_str() {
                    "-o" => "o",
                    _ => {
                        args.positional.push(word.clone());
                        continue;
                    }
                },
            };
            if let Some((name, value)) = name.split_once('=') {
                args.options.push((name.into(), Some(value.into())));
            } else if flags.contains(&name) {
                args.options.push((name.into(), None));
            } else {
                let value = it.next().ok_or(format!("--{name} needs a value"))?;
                args.options.push((name.into(), Some(value.clone())));
            }
        }
        Ok(args)
    }

    /// The next positional word.
    pub fn positional(&mut self, what: &str) -> Result<String, String> {
        match self.positional.is_empty() {
            true => Err(format!("missing {what}")),
            false => Ok(self.positional.remove(0)),
        }
    }

    /// Whether `--name` was given (a flag).
    pub fn flag(&mut self, name: &str) -> bool {
        self.take(name).is_some()
    }

    /// The value of `--name` (`o` stands for `-o`).
    pub fn value(&mut self, name: &str) -> Option<String> {
        self.take(name).flatten()
    }

    pub fn required(&mut self, name: &str) -> Result<String, String> {
        self.value(name)
            .ok_or_else(|| format!("missing {}", dashed(name)))
    }

    /// `--name` read as a `T`, or `default` when absent.
    pub fn number<T: FromStr>(&mut self, name: &str, default: T) -> Result<T, String> {
        match self.value(name) {
            None => Ok(default),
            Some(v) => v
                .parse()
                .map_err(|_| format!("{} {v}: not a number", dashed(name))),
        }
    }

    /// `--name X,Y`, if given.
    pub fn pair(&mut self, name: &str) -> Result<Option<[f64; 2]>, String> {
        let Some(v) = self.value(name) else {
            return Ok(None);
        };
        let bad = || format!("{} {v}: expected two numbers, X,Y", dashed(name));
        let (a, b) = v.split_once(',').ok_or_else(bad)?;
        Ok(Some([
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        ]))
    }

    fn take(&mut self, name: &str) -> Option<Option<String>> {
        let i = self.options.iter().position(|(n, _)| n == name)?;
        Some(self.options.remove(i).1)
    }

    /// Nothing may be left over.
    pub fn finish(self) -> Result<(), String> {
        if let Some((name, _)) = self.options.first() {
            return Err(format!("unknown option {}", dashed(name)));
        }
        if let Some(word) = self.positional.first() {
            return Err(format!("unexpected argument {word:?}"));
        }
        Ok(())
    }
}

fn dashed(name: &str) -> String {
    match name {
        "o" => "-o".into(),
        n => format!("--{n}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(words: &[&str]) -> Args {
        let raw: Vec<String> = words.iter().map(|w| w.to_string()).collect();
        Args::parse(&raw, &["quiet"]).unwrap()
    }

    #[test]
    fn options_flags_and_leftovers() {
        let mut a = args(&[
            "pic.png",
            "--nails=250",
            "-o",
            "card",
            "--quiet",
            "--at",
            "1, -2.5",
        ]);
        assert_eq!(a.positional("IMAGE").unwrap(), "pic.png");
        assert_eq!(a.number("nails", 0u16), Ok(250));
        assert_eq!(a.number("lines", 7usize), Ok(7));
        assert_eq!(a.required("o").unwrap(), "card");
        assert!(a.flag("quiet"));
        assert_eq!(a.pair("at"), Ok(Some([1.0, -2.5])));
        assert_eq!(a.pair("canny"), Ok(None));
        assert!(a.finish().is_ok());
        let mut a = args(&["--nails", "x", "--what", "1", "extra"]);
        assert_eq!(
            a.number("nails", 0u16),
            Err("--nails x: not a number".into())
        );
        assert_eq!(a.required("o"), Err("missing -o".into()));
        assert_eq!(a.finish().unwrap_err(), "unknown option --what");
        let raw = vec!["--nails".to_string()];
        assert_eq!(
            Args::parse(&raw, &[]).err(),
            Some("--nails needs a value".into())
        );
    }
}
