//! A few lines of SVG: documents sized in millimetres (1:1 when printed),
//! numbers with at most three decimals.

/// An SVG document whose user unit is the millimetre.
pub struct Svg {
    head: String,
    body: String,
    /// The view box: x, y (top left), width, height, mm.
    pub view: [f64; 4],
}

impl Svg {
    /// The view box `x`, `y` (top left), `width` × `height`, all mm.
    pub fn new(x: f64, y: f64, width: f64, height: f64) -> Svg {
        let head = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}mm\" height=\"{h}mm\" \
             viewBox=\"{} {} {w} {h}\">\n",
            num(x),
            num(y),
            w = num(width),
            h = num(height),
        );
        Svg {
            head,
            body: String::new(),
            view: [x, y, width, height],
        }
    }

    pub fn push(&mut self, element: &str) {
        self.body.push_str(element);
        self.body.push('\n');
    }

    /// The elements so far.
    pub fn body(&self) -> &str {
        &self.body
    }

    pub fn finish(self) -> String {
        format!("{}{}</svg>\n", self.head, self.body)
    }
}

/// `v` with at most three decimals, no trailing zeros.
pub fn num(v: f64) -> String {
    let s = format!("{:.3}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" => "0".into(),
        s => s.into(),
    }
}

/// Points as an SVG `points` attribute.
pub fn points(pts: impl IntoIterator<Item = [f64; 2]>) -> String {
    let all: Vec<String> = pts
        .into_iter()
        .map(|p| format!("{},{}", num(p[0]), num(p[1])))
        .collect();
    all.join(" ")
}

/// Text made safe for XML.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// An SVG document, by its bytes (not its name).
pub fn is_svg(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(512)]).to_ascii_lowercase();
    head.contains("<svg")
        || (head.trim_start().starts_with("<?xml")
            && String::from_utf8_lossy(bytes).contains("<svg"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_documents() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(-0.0001), "0");
        assert_eq!(num(2.5), "2.5");
        assert_eq!(num(1.23456), "1.235");
        assert_eq!(points([[0.0, 1.5], [2.0, -3.0]]), "0,1.5 2,-3");
        let mut s = Svg::new(-10.0, -10.0, 20.0, 20.0);
        s.push("<circle r=\"1\"/>");
        let doc = s.finish();
        assert!(doc.contains("width=\"20mm\"") && doc.contains("viewBox=\"-10 -10 20 20\""));
        assert!(doc.ends_with("<circle r=\"1\"/>\n</svg>\n"));
        assert_eq!(escape("a<b&c"), "a&lt;b&amp;c");
    }
}
