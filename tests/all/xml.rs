//! pinfeed's SVG output as a tree of elements, attributes and text (read with roxmltree), and
//! estimated boxes of an SVG's texts for the figure tests (`animate`, `figures`).

#[derive(Debug, Clone)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub text: String,
}

impl Element {
    pub fn attr(&self, k: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(a, _)| a == k)
            .map(|(_, v)| v.as_str())
    }
    /// Every element below (and including) this one, depth first.
    pub fn all(&self) -> Vec<&Element> {
        let mut out = vec![self];
        for c in &self.children {
            out.extend(c.all());
        }
        out
    }
    pub fn with_class(&self, class: &str) -> Vec<&Element> {
        self.all()
            .into_iter()
            .filter(|e| e.attr("class") == Some(class))
            .collect()
    }
    /// All text inside.
    pub fn inner_text(&self) -> String {
        let mut s = self.text.clone();
        for c in &self.children {
            s.push_str(&c.inner_text());
        }
        s
    }
}

/// Parse a document with one root element (with roxmltree); panics on anything ill-formed
/// (mismatched or duplicate names, unquoted values, unknown entities, text outside the root).
pub fn parse_xml(doc: &str) -> Element {
    let d = roxmltree::Document::parse(doc).expect("well-formed XML");
    element(d.root_element())
}

/// The tree below `node`, attribute names with their usual prefix (`xlink:href`, `xml:space`).
fn element(node: roxmltree::Node) -> Element {
    let attrs = node
        .attributes()
        .map(|a| {
            let prefix = match a.namespace() {
                Some("http://www.w3.org/1999/xlink") => "xlink:",
                Some("http://www.w3.org/XML/1998/namespace") => "xml:",
                _ => "",
            };
            (format!("{prefix}{}", a.name()), a.value().to_string())
        })
        .collect();
    let text = node
        .children()
        .filter(|c| c.is_text())
        .filter_map(|c| c.text())
        .collect();
    Element {
        name: node.tag_name().name().to_string(),
        attrs,
        children: node
            .children()
            .filter(|c| c.is_element())
            .map(element)
            .collect(),
        text,
    }
}

/// A text's estimated box (px, y down) and its content.
#[derive(Debug, Clone)]
pub struct TextBox {
    pub text: String,
    pub x0: f64,
    pub x1: f64,
    pub y0: f64,
    pub y1: f64,
    /// Key times it is shown over (a still text: 0–1).
    pub shown: (f64, f64),
    /// The nearest enclosing `class`, if any.
    pub class: Option<String>,
    /// Its `text-anchor`, if any.
    pub anchor: Option<String>,
}

impl TextBox {
    pub fn overlaps(&self, o: &TextBox) -> bool {
        self.x0 < o.x1
            && o.x0 < self.x1
            && self.y0 < o.y1
            && o.y0 < self.y1
            && self.shown.0 < o.shown.1
            && o.shown.0 < self.shown.1
    }
    /// Does the box cross the horizontal line at `y`?
    pub fn crosses(&self, y: f64) -> bool {
        self.y0 < y && y < self.y1
    }
}

fn number(s: Option<&str>) -> Option<f64> {
    s?.trim().trim_end_matches("px").parse().ok()
}

/// The key times a group fading in and out (`values="0;0;1;1;0;0"`, the animation's marks) is
/// shown over, from its `<animate attributeName="opacity">`.
fn shown_span(e: &Element) -> Option<(f64, f64)> {
    let a = e.children.iter().find(|c| {
        c.name == "animate" && c.attr("attributeName") == Some("opacity") && e.name == "g"
    })?;
    let values: Vec<&str> = a.attr("values")?.split(';').collect();
    let times: Vec<f64> = a
        .attr("keyTimes")?
        .split(';')
        .map(|t| t.parse().unwrap())
        .collect();
    let first = values.iter().position(|v| *v == "1")?;
    let last = values.iter().rposition(|v| *v == "1")?;
    // Shown until it has faded: the key after the last full opacity.
    Some((times[first], times[(last + 1).min(times.len() - 1)]))
}

/// The estimated boxes of every unrotated `<text>` under `root`: about 0.55 em a character
/// (0.6 bold), 1 em high (0.8 above the baseline); horizontal place from `text-anchor`, vertical
/// from plotters' `dy` (0.76em: top; 0.5ex: middle; -0.5ex: bottom), else the baseline. Font size
/// and weight are inherited from enclosing groups.
pub fn text_boxes(root: &Element) -> Vec<TextBox> {
    fn walk(
        e: &Element,
        size: f64,
        bold: bool,
        shown: (f64, f64),
        class: Option<&str>,
        out: &mut Vec<TextBox>,
    ) {
        let size = number(e.attr("font-size")).unwrap_or(size);
        let bold = e.attr("font-weight").map_or(bold, |w| w == "bold");
        let shown = shown_span(e).unwrap_or(shown);
        let class = e.attr("class").or(class);
        if e.name == "text" && e.attr("transform").is_none() {
            let text = e.inner_text().trim().to_string();
            let w = text.chars().count() as f64 * size * if bold { 0.6 } else { 0.55 };
            let x = number(e.attr("x")).unwrap_or(0.0);
            let y = number(e.attr("y")).unwrap_or(0.0);
            let x0 = match e.attr("text-anchor") {
                Some("middle") => x - w / 2.0,
                Some("end") => x - w,
                _ => x,
            };
            let top = match e.attr("dy") {
                Some("0.76em") => y,
                Some("0.5ex") => y - 0.5 * size,
                Some("-0.5ex") => y - size,
                _ => y - 0.8 * size,
            };
            if !text.is_empty() {
                out.push(TextBox {
                    text,
                    x0,
                    x1: x0 + w,
                    y0: top,
                    y1: top + size,
                    shown,
                    class: class.map(str::to_string),
                    anchor: e.attr("text-anchor").map(str::to_string),
                });
            }
        }
        for c in &e.children {
            walk(c, size, bold, shown, class, out);
        }
    }
    let mut out = Vec::new();
    walk(root, 16.0, false, (0.0, 1.0), None, &mut out);
    out
}

/// Every pair of boxes in `boxes` that overlap (shown at one time), as their texts.
pub fn overlapping(boxes: &[TextBox]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            if a.overlaps(b) {
                out.push((a.text.clone(), b.text.clone()));
            }
        }
    }
    out
}
