//! Drawing helpers on top of the `svg` crate: plan-to-pixel views, colour maps, colour bars,
//! scale bars and titles.

use svg::node::element::{
    Definitions, Group, Line, LinearGradient, Rectangle, Stop, Text as SvgText,
};
use svg::node::Blob;
use svg::Document;

pub const FONT: &str = "DejaVu Sans, Helvetica, Arial, sans-serif";

/// Maps plan points into a pixel rectangle with a uniform scale, y up.
#[derive(Debug, Clone, Copy)]
pub struct View {
    lo: [f64; 2],
    hi_y: f64,
    scale: f64,
    offset: [f64; 2],
}

/// Bounding box of `points`.
pub fn bbox(points: impl IntoIterator<Item = [f64; 2]>) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    if lo[0] > hi[0] {
        return ([0.0; 2], [1.0; 2]);
    }
    (lo, hi)
}

impl View {
    /// Fits the box `lo`..`hi` into the pixel rectangle (x, y, width, height), centred.
    pub fn fit(lo: [f64; 2], hi: [f64; 2], rect: [f64; 4]) -> View {
        let (w, h) = ((hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300));
        let scale = (rect[2] / w).min(rect[3] / h);
        View {
            lo,
            hi_y: hi[1],
            scale,
            offset: [
                rect[0] + (rect[2] - w * scale) / 2.0,
                rect[1] + (rect[3] - h * scale) / 2.0,
            ],
        }
    }

    pub fn px(&self, p: [f64; 2]) -> (f64, f64) {
        (
            self.offset[0] + (p[0] - self.lo[0]) * self.scale,
            self.offset[1] + (self.hi_y - p[1]) * self.scale,
        )
    }

    /// Pixels per plan unit.
    pub fn scale(&self) -> f64 {
        self.scale
    }
}

/// Linear interpolation in a list of equally spaced `0xrrggbb` stops, t in [0, 1], as red,
/// green and blue in [0, 255].
fn interpolate_rgb(stops: &[u32], t: f64) -> [f64; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (stops.len() - 1) as f64;
    let k = (x.floor() as usize).min(stops.len() - 2);
    let f = x - k as f64;
    let channel = |c: u32, shift: u32| ((c >> shift) & 0xff) as f64;
    let mix = |shift| {
        let (a, b) = (channel(stops[k], shift), channel(stops[k + 1], shift));
        a + (b - a) * f
    };
    [mix(16), mix(8), mix(0)]
}

/// `#rrggbb` of red, green and blue in [0, 255] (clamped).
pub fn hex(rgb: [f64; 3]) -> String {
    let [r, g, b] = rgb.map(|c| c.round().clamp(0.0, 255.0) as u8);
    format!("#{r:02x}{g:02x}{b:02x}")
}

fn interpolate(stops: &[u32], t: f64) -> String {
    hex(interpolate_rgb(stops, t))
}

/// Viridis: dark blue (low) to yellow (high). For force densities.
pub fn viridis(t: f64) -> String {
    const STOPS: [u32; 9] = [
        0x440154, 0x472d7b, 0x3b528b, 0x2c728e, 0x21918c, 0x28ae80, 0x5ec962, 0xaddc30, 0xfde725,
    ];
    interpolate(&STOPS, t)
}

/// Yellow (low) to dark red (high). For residuals.
pub fn heat(t: f64) -> String {
    const STOPS: [u32; 8] = [
        0xffffcc, 0xffeda0, 0xfed976, 0xfeb24c, 0xfd8d3c, 0xfc4e2a, 0xe31a1c, 0xb10026,
    ];
    interpolate(&STOPS, t)
}

/// Blue (t = 0, down) through a neutral grey-white (0.5) to red (1, up), as red, green and
/// blue in [0, 255]. For height changes.
pub fn diverging_rgb(t: f64) -> [f64; 3] {
    const STOPS: [u32; 7] = [
        0x2166ac, 0x67a9cf, 0xd1e5f0, 0xf7f7f7, 0xfddbc7, 0xef8a62, 0xb2182b,
    ];
    interpolate_rgb(&STOPS, t)
}

/// [`diverging_rgb`] as `#rrggbb`.
pub fn diverging(t: f64) -> String {
    hex(diverging_rgb(t))
}

pub fn text(x: f64, y: f64, size: f64, content: impl Into<String>) -> SvgText {
    SvgText::new(content)
        .set("x", x)
        .set("y", y)
        .set("font-family", FONT)
        .set("font-size", size)
        .set("fill", "#222")
}

/// A white page with a title and a subtitle line.
pub fn page(width: f64, height: f64, title: &str, subtitle: &str) -> Document {
    Document::new()
        .set("width", width)
        .set("height", height)
        .set("viewBox", (0, 0, width, height))
        .add(
            Rectangle::new()
                .set("width", width)
                .set("height", height)
                .set("fill", "white"),
        )
        .add(text(20.0, 30.0, 20.0, title).set("font-weight", "bold"))
        .add(text(20.0, 52.0, 13.0, subtitle).set("fill", "#555"))
}

/// A horizontal colour bar at (x, y) of width `w` with `ticks` (t in [0, 1], label) and a
/// caption above. `id` must be unique within the document.
pub fn colour_bar(
    id: &str,
    (x, y, w): (f64, f64, f64),
    colours: fn(f64) -> String,
    caption: &str,
    ticks: &[(f64, String)],
) -> Group {
    let mut gradient = LinearGradient::new().set("id", id);
    for k in 0..=16 {
        let t = k as f64 / 16.0;
        gradient = gradient.add(Stop::new().set("offset", t).set("stop-color", colours(t)));
    }
    let h = 12.0;
    let mut g = Group::new()
        .add(Definitions::new().add(gradient))
        .add(text(x, y - 6.0, 12.0, caption))
        .add(
            Rectangle::new()
                .set("x", x)
                .set("y", y)
                .set("width", w)
                .set("height", h)
                .set("fill", format!("url(#{id})"))
                .set("stroke", "#444")
                .set("stroke-width", 0.5),
        );
    for (t, label) in ticks {
        let tx = x + t.clamp(0.0, 1.0) * w;
        g = g
            .add(line((tx, y + h), (tx, y + h + 4.0), "#444", 1.0))
            .add(text(tx, y + h + 16.0, 11.0, label.clone()).set("text-anchor", "middle"));
    }
    g
}

/// The many elements of one group (a mesh's faces, edges or vertices), kept as their SVG text:
/// a picture of a large mesh then holds tens of bytes per element, not an element tree with
/// a map of attributes per element (about 1 GB for the pictures of a 100k-face mesh).
#[derive(Default)]
pub struct Bulk(String);

impl Bulk {
    pub fn add(mut self, node: impl svg::Node) -> Bulk {
        use std::fmt::Write;
        if !self.0.is_empty() {
            self.0.push('\n');
        }
        write!(self.0, "{node}").expect("writing to a String");
        self
    }

    /// `group` with the elements added after its children, written as `Group::add` would.
    pub fn into_group(self, group: Group) -> Group {
        if self.0.is_empty() {
            group
        } else {
            group.add(Blob::new(self.0))
        }
    }
}

pub fn line(a: (f64, f64), b: (f64, f64), colour: &str, width: f64) -> Line {
    Line::new()
        .set("x1", a.0)
        .set("y1", a.1)
        .set("x2", b.0)
        .set("y2", b.1)
        .set("stroke", colour)
        .set("stroke-width", width)
}

/// A round number (1, 2 or 5 × 10^k) close to but not above `x`.
pub fn nice(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return 1.0;
    }
    let p = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&v| v <= x)
        .unwrap_or(p)
}

/// Compact number formatting for labels.
pub fn fmt(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        format!("{x:.1e}")
    } else if a >= 100.0 {
        format!("{x:.0}")
    } else if a >= 1.0 {
        format!("{:.2}", x)
            .trim_end_matches('0')
            .trim_end_matches('.')
            .into()
    } else {
        format!("{x:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .into()
    }
}

/// A scale bar of a round length at most `max_px` pixels long, labelled with `unit`.
pub fn scale_bar(view: &View, (x, y): (f64, f64), max_px: f64, unit: &str) -> Group {
    let length = nice(max_px / view.scale());
    let px = length * view.scale();
    Group::new()
        .add(line((x, y), (x + px, y), "#222", 2.0))
        .add(line((x, y - 5.0), (x, y + 5.0), "#222", 1.5))
        .add(line((x + px, y - 5.0), (x + px, y + 5.0), "#222", 1.5))
        .add(
            text(
                x + px / 2.0,
                y - 8.0,
                12.0,
                format!("{} {unit}", fmt(length)),
            )
            .set("text-anchor", "middle"),
        )
}
