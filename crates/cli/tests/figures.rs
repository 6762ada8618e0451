//! The figures as a reader sees them: the real SVG, PNG and PDF files written by `drumroll`,
//! inspected for the defects a printed figure must not have. Text boxes come from `usvg`
//! laying out the SVG's text in the embedded font (independent of the layout code's own
//! measurements); curves are read back from the SVG's polylines.

mod common;

use std::path::Path;

use common::drumroll;
use drumroll::plot::raster;
use resvg::usvg;

/// A rectangle `(x0, y0, x1, y1)` in SVG pixels.
type Box2 = (f64, f64, f64, f64);

/// Run `drumroll ARGS` and require success.
fn run(args: &[&str]) {
    let output = drumroll().args(args).output().expect("runs");
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The value of attribute `name` in the element text `element`.
fn attribute<'a>(element: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = element.find(&key)? + key.len();
    let end = element[start..].find('"')? + start;
    Some(&element[start..end])
}

/// Every element `<tag ...>` of the document whose id starts with `prefix`, as
/// (id, element text up to its closing `>`, text content).
fn elements<'a>(svg: &'a str, tag: &str, prefix: &str) -> Vec<(&'a str, &'a str, &'a str)> {
    let open = format!("<{tag} ");
    svg.match_indices(&open)
        .filter_map(|(start, _)| {
            let end = svg[start..].find('>')? + start;
            let element = &svg[start..=end];
            let id = attribute(element, "id")?;
            if !id.starts_with(prefix) {
                return None;
            }
            let content = svg[end + 1..].split('<').next().unwrap_or_default();
            Some((id, element, content))
        })
        .collect()
}

/// The segments of panel `panel`'s curves (dots as zero-length segments), in SVG pixels.
fn curve_segments(svg: &str, panel: usize) -> Vec<((f64, f64), (f64, f64))> {
    let mut segments = Vec::new();
    for (_, element, _) in elements(svg, "polyline", &format!("p{panel}-curve-")) {
        let points: Vec<(f64, f64)> = attribute(element, "points")
            .expect("points")
            .split_whitespace()
            .map(|pair| {
                let (x, y) = pair.split_once(',').expect("x,y");
                (x.parse().expect("x"), y.parse().expect("y"))
            })
            .collect();
        segments.extend(points.windows(2).map(|w| (w[0], w[1])));
    }
    segments
}

/// Whether the segment from `a` to `b` has a point inside `rect` (sampled every 0.1 pixel:
/// independent of the layout code's clipping test).
fn segment_meets(rect: Box2, a: (f64, f64), b: (f64, f64)) -> bool {
    let length = (b.0 - a.0).hypot(b.1 - a.1);
    let steps = (length / 0.1).ceil().max(1.0) as usize;
    (0..=steps).any(|i| {
        let t = i as f64 / steps as f64;
        let (x, y) = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        x > rect.0 && x < rect.2 && y > rect.1 && y < rect.3
    })
}

fn overlap(a: Box2, b: Box2) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// The box of the text element `id` as usvg lays it out in the embedded font.
fn text_box(tree: &usvg::Tree, id: &str) -> Box2 {
    match tree.node_by_id(id) {
        Some(usvg::Node::Text(text)) => {
            let r = text.abs_bounding_box();
            (
                f64::from(r.left()),
                f64::from(r.top()),
                f64::from(r.right()),
                f64::from(r.bottom()),
            )
        }
        other => panic!("{id}: not a text node: {other:?}"),
    }
}

/// Every special-point label of panel `panel`: its text and box.
fn labels(svg: &str, tree: &usvg::Tree, panel: usize) -> Vec<(String, Box2)> {
    elements(svg, "text", &format!("p{panel}-label-"))
        .into_iter()
        .map(|(id, _, text)| (text.to_string(), text_box(tree, id)))
        .collect()
}

/// Labels of `panel` overlap no other label and no curve; the legend box meets no curve.
fn assert_labels_and_legend_clear(svg: &str, panel: usize) -> usize {
    let tree = raster::parse(svg).expect("the SVG parses");
    let labels = labels(svg, &tree, panel);
    let segments = curve_segments(svg, panel);
    assert!(!segments.is_empty(), "panel {panel} has curves");
    for (i, (text, a)) in labels.iter().enumerate() {
        for (other, b) in &labels[i + 1..] {
            assert!(
                !overlap(*a, *b),
                "panel {panel}: `{text}` {a:?} overlaps `{other}` {b:?}"
            );
        }
        for (p, q) in &segments {
            assert!(
                !segment_meets(*a, *p, *q),
                "panel {panel}: label `{text}` {a:?} covers the curve at {p:?}-{q:?}"
            );
        }
    }
    for (_, element, _) in elements(svg, "rect", &format!("p{panel}-legend")) {
        let number = |name| -> f64 {
            attribute(element, name)
                .expect(name)
                .parse()
                .expect("number")
        };
        let (x, y) = (number("x"), number("y"));
        let legend = (x, y, x + number("width"), y + number("height"));
        for (p, q) in &segments {
            assert!(
                !segment_meets(legend, *p, *q),
                "panel {panel}: the legend covers a curve"
            );
        }
    }
    labels.len()
}

#[test]
fn four_cases_draw_the_papers_fig2_one_titled_panel_per_case() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path().join("fig2.svg");
    let cases = [
        "biolever-mica",
        "biolever-soft",
        "maclever-mica",
        "maclever-soft",
    ];
    let mut args = vec!["continue"];
    for case in &cases {
        args.extend(["--case", case]);
    }
    args.extend(["--plot", path.to_str().expect("utf-8")]);
    run(&args);
    let svg = std::fs::read_to_string(&path).expect("written");
    for (panel, case) in cases.iter().enumerate() {
        let title = elements(&svg, "text", &format!("p{panel}-title-0"));
        let letter = char::from(b'a' + panel as u8);
        assert!(
            title
                .first()
                .is_some_and(|t| t.2.starts_with(&format!("({letter}) {case}: A0 = "))),
            "panel {panel} title: {title:?}"
        );
        let count = assert_labels_and_legend_clear(&svg, panel);
        assert!(count >= 2, "panel {panel} labels G1 and more: {count}");
    }
    assert!(svg.len() < 200_000, "{} bytes", svg.len());
}

#[test]
fn a_grazing_and_a_fold_thousandths_of_a_nm_apart_get_separate_labels() {
    // maclever-mica: G1 and a fold 0.003 nm apart in Z, on nearly the same pixel.
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path().join("maclever.svg");
    run(&[
        "continue",
        "--case",
        "maclever-mica",
        "--retract",
        "--plot",
        path.to_str().expect("utf-8"),
    ]);
    let svg = std::fs::read_to_string(&path).expect("written");
    for panel in [0, 1] {
        let tree = raster::parse(&svg).expect("parses");
        let texts: Vec<String> = labels(&svg, &tree, panel)
            .into_iter()
            .map(|l| l.0)
            .collect();
        assert!(
            texts.contains(&String::from("G1")) && texts.contains(&String::from("fold")),
            "{texts:?}"
        );
        assert_labels_and_legend_clear(&svg, panel);
    }
    assert!(
        svg.contains("<line class=\"leader\""),
        "set-off labels have leader lines"
    );
    // The retract is drawn in its own style (dash-dot over the approach's solid line).
    assert!(svg.contains("stroke-dasharray=\"9 3 2 3\""));
}

#[test]
fn the_impacts_axis_has_integer_ticks_and_every_axis_a_label_with_units() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path().join("biolever.svg");
    run(&[
        "continue",
        "--case",
        "biolever-mica",
        "--plot",
        path.to_str().expect("utf-8"),
    ]);
    let svg = std::fs::read_to_string(&path).expect("written");
    let ticks: Vec<&str> = elements(&svg, "text", "p2-ytick-")
        .into_iter()
        .map(|t| t.2)
        .collect();
    assert!(ticks.len() >= 3, "{ticks:?}");
    for tick in &ticks {
        assert!(
            tick.parse::<i64>().is_ok(),
            "impacts tick `{tick}` is not an integer"
        );
    }
    let ylabel = elements(&svg, "text", "p2-ylabel");
    assert_eq!(ylabel[0].2, "impacts per period");
    assert_eq!(
        elements(&svg, "text", "p1-xlabel")[0].2,
        "separation Z (nm)"
    );
    assert_eq!(elements(&svg, "text", "p0-ylabel")[0].2, "phase (deg)");
}

#[test]
fn overlay_draws_several_cases_on_one_set_of_axes_with_a_legend() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path().join("overlay.svg");
    run(&[
        "continue",
        "--case",
        "biolever-mica",
        "--case",
        "biolever-soft",
        "--overlay",
        "--plot",
        path.to_str().expect("utf-8"),
    ]);
    let svg = std::fs::read_to_string(&path).expect("written");
    let legend: Vec<&str> = elements(&svg, "text", "p0-legend-")
        .into_iter()
        .map(|t| t.2)
        .collect();
    assert!(
        legend.contains(&"biolever-mica") && legend.contains(&"biolever-soft"),
        "{legend:?}"
    );
    assert_eq!(
        elements(&svg, "g", "panel-").len(),
        3,
        "three shared panels"
    );
    for panel in 0..3 {
        assert_labels_and_legend_clear(&svg, panel);
    }
}

/// Width and height of an SVG document from its root element.
fn svg_size(svg: &str) -> (u32, u32) {
    let root = &svg[..svg.find('>').expect("root")];
    let number = |name| {
        attribute(root, name)
            .expect(name)
            .parse::<f64>()
            .expect("number") as u32
    };
    (number("width"), number("height"))
}

#[test]
fn png_and_pdf_follow_the_extension_at_the_svgs_size() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let base = |ext: &str| directory.path().join(format!("orbit.{ext}"));
    for ext in ["svg", "png", "pdf"] {
        run(&[
            "simulate",
            "--case",
            "biolever-mica",
            "--z",
            "8.5",
            "--plot",
            base(ext).to_str().expect("utf-8"),
        ]);
    }
    let svg = std::fs::read_to_string(base("svg")).expect("svg");
    let (width, height) = svg_size(&svg);
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(base("png")).expect("png"),
    ));
    let mut reader = decoder.read_info().expect("a PNG header");
    let info = reader.info();
    assert_eq!(
        (info.width, info.height),
        (2 * width, 2 * height),
        "PNG at twice the SVG size"
    );
    let mut pixels = vec![0; reader.output_buffer_size()];
    reader.next_frame(&mut pixels).expect("the image decodes");
    assert!(pixels.iter().any(|&p| p < 128), "something dark is drawn");
    let pdf = std::fs::read(base("pdf")).expect("pdf");
    assert!(pdf.starts_with(b"%PDF-") && pdf.len() > 1000);
    assert!(!Path::new(&base("jpg")).exists());
}

#[test]
fn a_long_approach_sweep_draws_in_under_500_kb() {
    // 10.2 nm down to 0 and back at 4 nm/s: about 47 000 lock-in readings, one dot each
    // before thinning (tens of bytes apiece: over a megabyte unthinned).
    let directory = tempfile::tempdir().expect("temporary directory");
    let svg_path = directory.path().join("sweep.svg");
    let csv = directory.path().join("sweep.csv");
    run(&[
        "approach",
        "--case",
        "biolever-mica",
        "--from",
        "10.2",
        "--to",
        "0",
        "--rate",
        "4",
        "--retract",
        "--out",
        csv.to_str().expect("utf-8"),
        "--plot",
        svg_path.to_str().expect("utf-8"),
    ]);
    let records = std::fs::read_to_string(&csv)
        .expect("records")
        .lines()
        .count();
    assert!(records > 40_000, "{records} records");
    let size = std::fs::metadata(&svg_path).expect("svg").len();
    assert!(size < 500_000, "the approach figure is {size} bytes");
    let svg = std::fs::read_to_string(&svg_path).expect("svg");
    assert!(
        svg.contains("stroke-width=\"1.4\""),
        "the retract has its own (finer) dots"
    );
}

/// The regime map (Biolever on mica over A0 = 5..20 nm: G1, G2, G3 in both planes): every
/// region name is written once per plane, and none covers a curve, another name, a label or
/// the legend; the same figure is written as PNG and PDF by the extension.
#[test]
fn the_regime_map_names_its_regions_clear_of_curves_labels_and_legend() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path().join("map.svg");
    let map = [
        "map",
        "--case",
        "biolever-mica",
        "--vary",
        "a0",
        "--from",
        "5",
        "--to",
        "20",
    ];
    run(&[&map[..], &["--plot", path.to_str().expect("utf-8")]].concat());
    let svg = std::fs::read_to_string(&path).expect("svg");
    let tree = raster::parse(&svg).expect("the SVG parses");
    for panel in 0..2 {
        assert_labels_and_legend_clear(&svg, panel);
        let names: Vec<(String, Box2)> = elements(&svg, "text", &format!("p{panel}-region-"))
            .into_iter()
            .map(|(id, _, text)| (text.to_string(), text_box(&tree, id)))
            .collect();
        let texts: Vec<&str> = names.iter().map(|(t, _)| t.as_str()).collect();
        assert_eq!(
            texts,
            ["no impact", "1 impact", "2 impacts", "3 impacts"],
            "panel {panel}"
        );
        let segments = curve_segments(&svg, panel);
        let others = labels(&svg, &tree, panel);
        for (i, (text, a)) in names.iter().enumerate() {
            for (p, q) in &segments {
                assert!(
                    !segment_meets(*a, *p, *q),
                    "panel {panel}: `{text}` {a:?} covers the curve at {p:?}-{q:?}"
                );
            }
            for (other, b) in names[i + 1..].iter().chain(&others) {
                assert!(
                    !overlap(*a, *b),
                    "panel {panel}: `{text}` overlaps `{other}`"
                );
            }
            if let Some((_, element, _)) =
                elements(&svg, "rect", &format!("p{panel}-legend")).first()
            {
                let number = |name| -> f64 {
                    attribute(element, name)
                        .expect(name)
                        .parse()
                        .expect("number")
                };
                let (x, y) = (number("x"), number("y"));
                let legend = (x, y, x + number("width"), y + number("height"));
                assert!(
                    !overlap(*a, legend),
                    "panel {panel}: `{text}` under the legend"
                );
            }
        }
    }
    for (name, magic) in [("map.png", &b"\x89PNG"[..]), ("map.pdf", &b"%PDF-"[..])] {
        let file = directory.path().join(name);
        run(&[&map[..], &["--plot", file.to_str().expect("utf-8")]].concat());
        let bytes = std::fs::read(&file).expect(name);
        assert!(bytes.starts_with(magic) && bytes.len() > 1000, "{name}");
    }
}
