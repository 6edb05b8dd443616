//! A small XML reader for the tests of `formfind`'s SVG pictures: enough to check that a
//! picture is well formed and to read its elements' attributes, without an XML crate.

use std::collections::HashMap;

/// An element of the SVG: its name and attributes, in document order.
pub struct Element {
    pub name: String,
    pub attributes: HashMap<String, String>,
    /// The `id` of the nearest enclosing element that has one.
    pub parent_id: Option<String>,
}

/// Parses `text` as XML far enough to check it is well formed (tags balanced and properly
/// nested, one root, quoted attributes, known entities) and returns its elements.
pub fn parse_xml(text: &str) -> Vec<Element> {
    let mut elements = Vec::new();
    // (name, id) of the open elements.
    let mut open: Vec<(String, Option<String>)> = Vec::new();
    let mut roots = 0;
    let mut rest = text;
    while let Some(start) = rest.find('<') {
        check_entities(&rest[..start]);
        rest = &rest[start..];
        if let Some(after) = rest.strip_prefix("<!--") {
            let end = after.find("-->").expect("unterminated comment");
            rest = &after[end + 3..];
            continue;
        }
        if let Some(after) = rest.strip_prefix("<?") {
            let end = after.find("?>").expect("unterminated declaration");
            rest = &after[end + 2..];
            continue;
        }
        let end = rest.find('>').expect("unterminated tag");
        let tag = &rest[1..end];
        rest = &rest[end + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let (open_name, _) = open.pop().unwrap_or_else(|| panic!("stray </{name}>"));
            assert_eq!(
                open_name,
                name.trim(),
                "</{}> closes <{open_name}>",
                name.trim()
            );
            continue;
        }
        let self_closing = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let name_end = tag.find(char::is_whitespace).unwrap_or(tag.len());
        let name = &tag[..name_end];
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_alphanumeric() || c == '-'),
            "bad tag name in <{tag}>"
        );
        let attributes = parse_attributes(&tag[name_end..]);
        if open.is_empty() {
            roots += 1;
        }
        let parent_id = open.iter().rev().find_map(|(_, id)| id.clone());
        if !self_closing {
            let id = attributes.get("id").cloned().or(parent_id.clone());
            open.push((name.to_string(), id));
        }
        elements.push(Element {
            name: name.to_string(),
            attributes,
            parent_id,
        });
    }
    assert!(rest.trim().is_empty(), "text after the root element");
    assert!(open.is_empty(), "unclosed elements: {open:?}");
    assert_eq!(roots, 1, "one root element");
    elements
}

/// `name="value"` pairs separated by white space.
fn parse_attributes(mut text: &str) -> HashMap<String, String> {
    let mut attributes = HashMap::new();
    loop {
        text = text.trim_start();
        if text.is_empty() {
            return attributes;
        }
        let eq = text
            .find('=')
            .unwrap_or_else(|| panic!("attribute without value: {text}"));
        let name = text[..eq].trim();
        assert!(
            name.chars()
                .all(|c| c.is_alphanumeric() || c == '-' || c == ':'),
            "bad attribute name `{name}`"
        );
        let value = text[eq + 1..]
            .strip_prefix('"')
            .unwrap_or_else(|| panic!("unquoted attribute `{name}`"));
        let close = value.find('"').expect("unterminated attribute value");
        check_entities(&value[..close]);
        let old = attributes.insert(name.to_string(), value[..close].to_string());
        assert!(old.is_none(), "attribute `{name}` given twice");
        text = &value[close + 1..];
    }
}

fn check_entities(text: &str) {
    assert!(!text.contains('<'), "`<` in text or attribute");
    for (i, _) in text.match_indices('&') {
        let entity = &text[i..];
        assert!(
            ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;", "&#"]
                .iter()
                .any(|e| entity.starts_with(e)),
            "unknown entity at `{}`",
            &entity[..entity.len().min(8)]
        );
    }
}
