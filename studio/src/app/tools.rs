//! The host tools as the page calls them: a file's bytes and the CLI's
//! options (query parameters named as its flags, `width_mm` for
//! `--width-mm`) in, JSON out. Each is the library call the command line
//! makes (`vectorize`, `text`, `stringart`, `toolpath`, `template`), so
//! the page shows what the CLI would write.

use super::Bad;
use crate::gray::Gray;
use crate::hershey::Font;
use crate::raster::Canvas;
use crate::send::stream::lines_of;
use crate::send::Eta;
use crate::stringart::card::{self, Spec};
use crate::stringart::{self, picture};
use crate::toolpath::{self, Toolpath};
use crate::vectorize::{self, svgfile, Mode};
use crate::{plot, progress, template, text};
use base64::Engine;
use serde_json::{json, Value};
use std::collections::HashMap;
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;

/// The query's options, read as the CLI reads its flags.
pub struct Query(pub HashMap<String, String>);

impl Query {
    fn text(&self, name: &str) -> Option<&str> {
        self.0.get(name).map(String::as_str)
    }

    fn required(&self, name: &str) -> Result<&str, Bad> {
        self.text(name)
            .ok_or_else(|| Bad::input(format!("missing {name}")))
    }

    fn number<T: std::str::FromStr>(&self, name: &str, default: T) -> Result<T, Bad> {
        match self.text(name) {
            None | Some("") => Ok(default),
            Some(v) => v
                .parse()
                .map_err(|_| Bad::input(format!("{name}={v}: not a number"))),
        }
    }

    fn pair(&self, name: &str) -> Result<Option<[f64; 2]>, Bad> {
        let Some(v) = self.text(name).filter(|v| !v.is_empty()) else {
            return Ok(None);
        };
        let bad = || Bad::input(format!("{name}={v}: expected two numbers, X,Y"));
        let (a, b) = v.split_once(',').ok_or_else(bad)?;
        Ok(Some([
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        ]))
    }

    /// A plotter (`machine=`, default the flatbed).
    fn plotter(&self) -> Result<Machine, Bad> {
        plot::machine(self.text("machine").unwrap_or("flatbed")).map_err(Bad::input)
    }
}

/// PNG bytes of a canvas, base64 for JSON.
fn png_base64(c: &Canvas) -> String {
    let mut bytes = Vec::new();
    let mut png = png::Encoder::new(&mut bytes, c.cols as u32, c.rows as u32);
    png.set_color(png::ColorType::Rgb);
    png.set_depth(png::BitDepth::Eight);
    // Encoding into memory fails only on a wrong buffer size.
    let mut w = png.write_header().expect("PNG header");
    w.write_image_data(&c.rgb).expect("PNG data");
    w.finish().expect("PNG end");
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// The widest drawing the machine's travel takes, mm: its X travel where
/// soft limits keep it (the drum, the flatbed); the hanging plotter and
/// the arm refuse what they cannot reach when the G-code is read back.
pub fn width_max_mm(machine: Machine) -> Option<f64> {
    let x = MachineConfig::defaults(machine).axes[0];
    match (machine, x.soft_limits) {
        (Machine::Drum | Machine::Flatbed, true) => {
            Some(f64::from(x.travel.1 .0 - x.travel.0 .0) / 1000.0)
        }
        _ => None,
    }
}

/// The machine time of a program by the firmware's planner, s.
pub fn estimate_s(gcode: &[u8], machine: Machine) -> f64 {
    Eta::of(&lines_of(gcode), &MachineConfig::defaults(machine)).total
}

/// A drawing's answer: its G-code, the toolpath (the page draws it and
/// the travelled path over it), the time and the pen's travel.
fn drawing(gcode: String, path: &Toolpath, machine: Machine) -> Value {
    let (down, up) = path.lengths();
    let (lo, hi) = path.bounds();
    let r = |v: f64| (v * 1000.0).round() / 1000.0;
    let moves: Vec<Value> = path
        .moves
        .iter()
        .map(|m| {
            json!([
                r(m.from[0]),
                r(m.from[1]),
                r(m.to[0]),
                r(m.to[1]),
                u8::from(m.down)
            ])
        })
        .collect();
    json!({
        "machine": machine.name().to_string(),
        "estimate_s": estimate_s(gcode.as_bytes(), machine),
        "lines": gcode.lines().count(),
        "pen_down_mm": down,
        "pen_up_mm": up,
        "bounds": [lo, hi],
        "toolpath": moves,
        "preview_png": png_base64(&crate::render::png(path, 600)),
        "gcode": gcode,
    })
}

/// The modes `mode=` takes, as `taut vectorize --mode`.
const MODES: &str = "edges, hatch, outline, centerline or auto";

/// `POST /api/vectorize`: a picture (PNG, JPEG) or an SVG drawing to
/// plotter G-code. An SVG is drawn from its shapes at its own size unless
/// `width_mm` scales its page; a picture needs `width_mm` (default 60).
pub fn vectorize(bytes: &[u8], q: &Query) -> Result<Value, Bad> {
    if bytes.is_empty() {
        return Err(Bad::input("no picture: the body is empty".into()));
    }
    let machine = q.plotter()?;
    let source = match crate::svg::is_svg(bytes) {
        true => vectorize::Source::Svg(svgfile::read(bytes).map_err(Bad::input)?),
        false => vectorize::Source::Picture(
            Gray::decode(bytes).map_err(|e| Bad::input(format!("the picture: {e}")))?,
        ),
    };
    let own = match &source {
        vectorize::Source::Svg(d) => Some(d.size[0]),
        vectorize::Source::Picture(_) => None,
    };
    let mut width = match (q.text("width_mm").filter(|w| !w.is_empty()), own) {
        (None, Some(own)) => own,
        _ => q.number("width_mm", 60.0f64)?,
    };
    let mut notes = Vec::new();
    if let Some(max) = width_max_mm(machine).filter(|&m| width > m) {
        notes.push(format!(
            "width {} mm kept within the {}'s travel: {max} mm",
            (width * 10.0).round() / 10.0,
            machine.name()
        ));
        width = max;
    }
    let mut o = vectorize::Options::new(machine, width);
    // The page's two modes (Canny edges; hatching at the tone levels), or
    // any of the CLI's `--mode`.
    o.mode = match q.text("mode").unwrap_or("edges") {
        "" => Mode::Edges,
        m => <Mode as clap::ValueEnum>::from_str(m, true)
            .map_err(|_| Bad::input(format!("mode={m}: {}", MODES)))?,
    };
    if let Some([low, high]) = q.pair("canny")? {
        o.canny = [low as f32, high as f32];
    }
    if q.text("threshold").is_some_and(|t| !t.is_empty()) {
        o.threshold = Some(q.number("threshold", 0.5f32)?);
    }
    o.hatch_mm = q.number("hatch_mm", o.hatch_mm)?;
    o.angle = q.number("angle", o.angle)?;
    o.blur = q.number("blur", o.blur)?;
    if q.text("tolerance_mm").is_some_and(|t| !t.is_empty()) {
        o.tolerance_mm = Some(q.number("tolerance_mm", 0.0)?);
    }
    if q.text("min_length_mm").is_some_and(|t| !t.is_empty()) {
        o.min_length_mm = Some(q.number("min_length_mm", 0.0)?);
    }
    o.one_pen = q.text("one_pen").is_some_and(|v| v == "1" || v == "true");
    o.layout.at = q.pair("at")?;
    o.feed = q.number("feed", o.feed)?;
    let title = format!("taut studio {}", q.text("name").unwrap_or("picture"));
    let v = vectorize::vectorize(&source, &o, &title).map_err(Bad::input)?;
    notes.extend(v.warnings.iter().cloned());
    let mut out = drawing(v.gcode, &v.toolpath, machine);
    out["strokes"] = json!(v.strokes.len());
    out["layers"] = json!(v.layers.len());
    out["svg"] = json!(own.is_some());
    out["pen_up_traced_mm"] = json!(v.pen_up_traced_mm);
    out["width_mm"] = json!(width);
    out["width_max_mm"] = json!(width_max_mm(machine));
    out["note"] = json!((!notes.is_empty()).then(|| notes.join("; ")));
    Ok(out)
}

/// `POST /api/text`: the body (or `text=`) in a Hershey font.
pub fn text(body: &[u8], q: &Query) -> Result<Value, Bad> {
    let body =
        String::from_utf8(body.to_vec()).map_err(|_| Bad::input("the text is not UTF-8".into()))?;
    let words = match body.is_empty() {
        true => q.required("text")?.to_string(),
        false => body,
    };
    let machine = q.plotter()?;
    let font = Font::named(q.text("font").unwrap_or("futural")).map_err(Bad::input)?;
    let height = q.number("height_mm", 10.0)?;
    let wrap = match q.text("wrap_mm") {
        None | Some("") => None,
        Some(_) => Some(q.number("wrap_mm", 0.0)?),
    };
    let feed = q.number("feed", 1500.0)?;
    let placed = text::strokes(&font, &words, height, wrap, [0.0, 0.0]).map_err(Bad::input)?;
    let size = placed
        .iter()
        .flatten()
        .fold([0.0f64; 2], |s, p| [s[0].max(p[0]), s[1].max(p[1])]);
    let corner = q
        .pair("at")?
        .unwrap_or_else(|| plot::default_corner(machine, size));
    let shifted = text::strokes(&font, &words, height, wrap, corner).map_err(Bad::input)?;
    let (gcode, path) =
        plot::plot(&shifted, machine, feed, &format!("taut text {words}")).map_err(Bad::input)?;
    Ok(drawing(gcode, &path, machine))
}

/// `POST /api/gcode`: a G-code file read as the machine reads it (its
/// parser and interpreter): the toolpath, or the first line it refuses.
pub fn gcode(bytes: &[u8], q: &Query) -> Result<Value, Bad> {
    let machine = q.plotter()?;
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Bad::input(format!("not a text file (byte {})", e.valid_up_to() + 1)))?;
    if text.trim().is_empty() {
        return Err(Bad::input("the G-code file is empty".into()));
    }
    let path =
        toolpath::from_gcode(text, machine).map_err(|e| Bad::input(format!("the G-code, {e}")))?;
    if path.moves.is_empty() {
        return Err(Bad::input("the G-code moves nowhere".into()));
    }
    Ok(drawing(text.to_string(), &path, machine))
}

/// The board of `shape`, `nails`, `radius_cm` (as `--shape` …).
pub fn spec(q: &Query) -> Result<Spec, Bad> {
    let shape = match q.text("shape").unwrap_or("circle") {
        "circle" | "" => 0,
        n => n
            .parse()
            .map_err(|_| Bad::input(format!("shape={n}: circle or a number of sides")))?,
    };
    let radius_cm: f64 = q.number("radius_cm", 20.0)?;
    if !(radius_cm > 0.0 && radius_cm <= 1000.0) {
        return Err(Bad::input(
            "radius_cm must be above 0 and at most 1000".into(),
        ));
    }
    let spec = Spec {
        shape,
        nails: q.number("nails", 200u16)?,
        radius_um: (radius_cm * 10_000.0).round() as u32,
    };
    spec.board().map_err(Bad::input)?;
    Ok(spec)
}

/// The picture framed as the string-art panel's crop controls say: the
/// square of side `1/zoom` of the shorter side centred at `cx`, `cy`
/// (fractions of the width and height), its contrast stretched about mid
/// grey.
pub fn frame(image: &Gray, q: &Query) -> Result<Gray, Bad> {
    let zoom = q.number("zoom", 1.0f64)?;
    let (cx, cy) = (q.number("cx", 0.5f64)?, q.number("cy", 0.5f64)?);
    let contrast = q.number("contrast", 1.0f32)?;
    if !(1.0..=20.0).contains(&zoom) || !(0.0..=1.0).contains(&cx) || !(0.0..=1.0).contains(&cy) {
        return Err(Bad::input("zoom is 1 to 20, cx and cy 0 to 1".into()));
    }
    if !(0.1..=10.0).contains(&contrast) {
        return Err(Bad::input("contrast is 0.1 to 10".into()));
    }
    let side = ((image.width.min(image.height) as f64 / zoom).round() as usize).max(1);
    let at = |c: f64, len: usize| {
        ((c * len as f64 - side as f64 / 2.0).round().max(0.0) as usize).min(len - side)
    };
    let (x0, y0) = (at(cx, image.width), at(cy, image.height));
    let mut out = Gray::new(side, side, 1.0);
    for y in 0..side {
        for x in 0..side {
            let v = image.at(x0 + x, y0 + y);
            out.pixels[y * side + x] = (0.5 + (v - 0.5) * contrast).clamp(0.0, 1.0);
        }
    }
    Ok(out)
}

/// `POST /api/stringart`: a picture to a card, and what it costs.
pub fn stringart(bytes: &[u8], q: &Query) -> Result<Value, Bad> {
    if bytes.is_empty() {
        return Err(Bad::input("no picture: the body is empty".into()));
    }
    let spec = spec(q)?;
    let mut o = stringart::Options::new(spec, q.number("lines", 1000usize)?);
    o.thread_mm = q.number("thread_mm", o.thread_mm)?;
    o.resolution = q.number("resolution", 256usize)?;
    o.seed = q.number("seed", o.seed)?;
    if o.lines > 20_000 {
        return Err(Bad::input("lines: at most 20 000 in the studio".into()));
    }
    let image = Gray::decode(bytes).map_err(|e| Bad::input(format!("the picture: {e}")))?;
    let framed = frame(&image, q)?;
    let w = stringart::generate(&framed, &o, &progress::quiet()).map_err(Bad::input)?;
    let (param, poradi) = (spec.param_txt(), card::poradi_txt(&w.pattern));
    card::check(param.as_bytes(), poradi.as_bytes()).map_err(Bad::input)?;
    let board = spec.board().map_err(Bad::input)?;
    let (drilling_s, winding_s) =
        card::machine_seconds(param.as_bytes(), poradi.as_bytes()).map_err(Bad::input)?;
    let px = q.number("preview_px", 600usize)?.clamp(64, 2000);
    let thread = f64::from(o.thread_mm);
    // The framed picture as the generator saw it, beside the preview.
    let mut seen = Canvas::new(framed.width, framed.height, [255; 3]);
    for (i, v) in framed.pixels.iter().enumerate() {
        let g = (v * 255.0).round() as u8;
        seen.rgb[i * 3..][..3].copy_from_slice(&[g, g, g]);
    }
    Ok(json!({
        "param": param,
        "poradi": poradi,
        "lines": w.pattern.len(),
        "rmse": w.rmse,
        "generated_s": w.seconds,
        "estimate_s": drilling_s + winding_s,
        "drilling_s": drilling_s,
        "winding_s": winding_s,
        "thread_m": card::thread_mm(&board, &w.pattern) / 1000.0,
        "preview_png": png_base64(&picture::png(&board, &w.pattern, thread, px)),
        "framed_png": png_base64(&seen),
    }))
}

/// A card's files from its `poradi.txt` (the body) and its board (the
/// query), checked by the firmware's parsers as the card writer does.
pub fn card_files(poradi: &[u8], q: &Query) -> Result<(Spec, Vec<u16>), Bad> {
    let spec = spec(q)?;
    let pattern = card::check(spec.param_txt().as_bytes(), poradi).map_err(Bad::input)?;
    Ok((spec, pattern))
}

/// `POST /api/card?dir=PATH`: the card written into a folder (a card
/// mounted on this computer, or any folder to copy from).
pub fn write_card(poradi: &[u8], q: &Query) -> Result<Value, Bad> {
    let dir = std::path::PathBuf::from(q.required("dir")?);
    let (spec, pattern) = card_files(poradi, q)?;
    let mut o = stringart::Options::new(spec, pattern.len());
    o.thread_mm = q.number("thread_mm", o.thread_mm)?;
    let c = stringart::write_card(&dir, &o, &pattern, 1200).map_err(Bad::input)?;
    Ok(json!({
        "dir": dir,
        "files": ["param.txt", "poradi.txt", "preview.png", "preview.svg"],
        "thread_m": c.thread_m,
        "estimate_s": c.drilling_s + c.winding_s,
    }))
}

/// `GET /api/template`: the 1:1 drilling template (SVG).
pub fn template(q: &Query) -> Result<String, Bad> {
    template::template(&spec(q)?).map_err(Bad::input)
}

/// The machines the page offers, with what it needs to know of each.
pub fn machines() -> Value {
    let all = [
        Machine::StringArt,
        Machine::Drum,
        Machine::Flatbed,
        Machine::Whiteboard,
        Machine::Scara,
    ];
    json!(all
        .iter()
        .map(|&m| json!({
            "name": m.name().to_string(),
            "plotter": !m.is_string_art(),
            "width_max_mm": width_max_mm(m),
        }))
        .collect::<Vec<_>>())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(pairs: &[(&str, &str)]) -> Query {
        Query(
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        )
    }

    #[test]
    fn framing_crops_zooms_and_stretches() {
        let mut g = Gray::new(40, 20, 1.0);
        g.pixels[5 * 40 + 30] = 0.25;
        let f = frame(
            &g,
            &q(&[
                ("zoom", "2"),
                ("cx", "0.75"),
                ("cy", "0.5"),
                ("contrast", "2"),
            ]),
        )
        .unwrap();
        // A 10-pixel square from (25, 5).
        assert_eq!((f.width, f.height), (10, 10));
        assert_eq!(f.at(5, 0), 0.0, "0.25 stretched twice about 0.5");
        assert_eq!(f.at(0, 0), 1.0);
        assert!(frame(&g, &q(&[("zoom", "0.5")])).is_err());
    }

    #[test]
    fn the_flatbed_keeps_a_drawing_within_its_travel() {
        assert_eq!(width_max_mm(Machine::Flatbed), Some(140.0));
        assert_eq!(width_max_mm(Machine::Scara), None);
    }
}
