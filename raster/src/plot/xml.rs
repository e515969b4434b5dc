//! The XML of the SVG charts: escaping text, and a well-formedness check.
//!
//! [`escape`] makes any string safe as element text or attribute value. [`check_well_formed`]
//! checks what [`render_chart`](super::render_chart) writes — and any other document of the
//! same subset — at the level of a parser: one root element, every tag closed in order,
//! attributes quoted, entities known. It is what the tests of the charts and of
//! `lucent bench` run on every SVG; it is not a validating or complete XML parser (no DTD,
//! no CDATA sections, no processing instructions beyond the XML declaration).

/// `text` with the five XML special characters escaped (and control characters, which XML
/// 1.0 does not allow, replaced by a space).
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if c.is_control() && c != '\n' && c != '\t' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Checks that `xml` is a well-formed document of the subset described in the [module
/// documentation](self); returns the root element's name, or what is wrong and at which
/// byte.
pub fn check_well_formed(xml: &str) -> Result<String, String> {
    let mut rest = xml;
    let at = |rest: &str| xml.len() - rest.len();
    if let Some(after) = rest.strip_prefix("<?xml") {
        let end = after
            .find("?>")
            .ok_or("the XML declaration is not closed")?;
        rest = &after[end + 2..];
    }
    let mut open: Vec<&str> = Vec::new();
    let mut root: Option<String> = None;
    loop {
        let text_end = rest.find('<').unwrap_or(rest.len());
        let text = &rest[..text_end];
        if open.is_empty() && !text.trim().is_empty() {
            return Err(format!(
                "text outside the root element at byte {}",
                at(rest)
            ));
        }
        check_text(text).map_err(|e| format!("{e} at byte {}", at(rest)))?;
        rest = &rest[text_end..];
        if rest.is_empty() {
            break;
        }
        if let Some(after) = rest.strip_prefix("<!--") {
            let end = after
                .find("-->")
                .ok_or_else(|| format!("unclosed comment at byte {}", at(rest)))?;
            rest = &after[end + 3..];
            continue;
        }
        let end = rest
            .find('>')
            .ok_or_else(|| format!("unclosed tag at byte {}", at(rest)))?;
        let tag = &rest[1..end];
        let position = at(rest);
        rest = &rest[end + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            match open.pop() {
                Some(expected) if expected == name.trim_end() => {}
                Some(expected) => {
                    return Err(format!("</{name}> closes <{expected}> at byte {position}"));
                }
                None => return Err(format!("</{name}> closes nothing at byte {position}")),
            }
            continue;
        }
        let (body, empty) = match tag.strip_suffix('/') {
            Some(body) => (body, true),
            None => (tag, false),
        };
        let name_end = body.find(|c: char| c.is_whitespace()).unwrap_or(body.len());
        let name = &body[..name_end];
        if !is_name(name) {
            return Err(format!("bad tag name '{name}' at byte {position}"));
        }
        check_attributes(&body[name_end..])
            .map_err(|e| format!("<{name}>: {e} at byte {position}"))?;
        if open.is_empty() {
            if root.is_some() {
                return Err(format!("a second root element <{name}> at byte {position}"));
            }
            root = Some(name.to_string());
        }
        if !empty {
            open.push(name);
        }
    }
    if let Some(name) = open.last() {
        return Err(format!("<{name}> is never closed"));
    }
    root.ok_or_else(|| "no root element".to_string())
}

fn is_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | ':' | '.'))
}

/// Text and attribute values: no raw `<`, every `&` starts a known entity.
fn check_text(text: &str) -> Result<(), String> {
    if text.contains('<') {
        return Err("a raw '<'".to_string());
    }
    let mut rest = text;
    while let Some(i) = rest.find('&') {
        let after = &rest[i + 1..];
        let end = after.find(';').ok_or("an '&' without ';'")?;
        let entity = &after[..end];
        let known = matches!(entity, "amp" | "lt" | "gt" | "quot" | "apos")
            || entity
                .strip_prefix('#')
                .is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()));
        if !known {
            return Err(format!("unknown entity '&{entity};'"));
        }
        rest = &after[end + 1..];
    }
    Ok(())
}

/// `name="value"` pairs separated by white space, each name once.
fn check_attributes(mut rest: &str) -> Result<(), String> {
    let mut seen: Vec<&str> = Vec::new();
    loop {
        rest = rest.trim_start();
        if rest.is_empty() {
            return Ok(());
        }
        let eq = rest.find('=').ok_or("an attribute without a value")?;
        let name = rest[..eq].trim_end();
        if !is_name(name) {
            return Err(format!("bad attribute name '{name}'"));
        }
        if seen.contains(&name) {
            return Err(format!("attribute '{name}' twice"));
        }
        seen.push(name);
        let value = rest[eq + 1..].trim_start();
        let quote = value
            .chars()
            .next()
            .filter(|&q| q == '"' || q == '\'')
            .ok_or_else(|| format!("attribute '{name}' is not quoted"))?;
        let close = value[1..]
            .find(quote)
            .ok_or_else(|| format!("attribute '{name}' is not closed"))?;
        check_text(&value[1..1 + close]).map_err(|e| format!("attribute '{name}': {e}"))?;
        let after = &value[1 + close + 1..];
        if !after.is_empty() && !after.starts_with(char::is_whitespace) {
            return Err(format!("no space after attribute '{name}'"));
        }
        rest = after;
    }
}
