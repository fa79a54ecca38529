//! A small XML parser for the subset the VTK XML readers need: elements, attributes, character
//! data, the five predefined entities and numeric character references; declarations,
//! processing instructions, comments and `DOCTYPE`s are skipped. `CDATA` sections are not
//! supported (VTK's ASCII files do not use them).
//!
//! Hand-written rather than a dependency because the readers need the **line number** of every
//! element and of the first character of its text (to report bad numbers precisely), the
//! subset is tiny, and the parser must never panic or recurse without bound (nesting is limited
//! to [`MAX_DEPTH`] levels, and the tree is dropped iteratively).

use std::path::Path;

use crate::error::IoError;

/// Deepest element nesting accepted (VTK files use 5 or 6 levels).
pub(crate) const MAX_DEPTH: usize = 64;

/// One element with its attributes, children and concatenated character data.
#[derive(Debug, Default)]
pub(crate) struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub text: String,
    /// 1-based line of the `<` that opens the element.
    pub line: usize,
    /// 1-based line where `text` starts.
    pub text_line: usize,
}

impl Element {
    /// The value of an attribute.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The children with this name.
    pub fn children_named<'s>(&'s self, name: &'s str) -> impl Iterator<Item = &'s Element> {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// The first child with this name.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
}

impl Drop for Element {
    /// Iterative drop so that a deep tree cannot overflow the stack.
    fn drop(&mut self) {
        let mut stack = std::mem::take(&mut self.children);
        while let Some(mut e) = stack.pop() {
            stack.append(&mut e.children);
        }
    }
}

struct Cursor<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
    path: &'a Path,
}

impl<'a> Cursor<'a> {
    fn rest(&self) -> &'a str {
        self.text.get(self.pos..).unwrap_or("")
    }

    fn advance(&mut self, n: usize) {
        let end = (self.pos + n).min(self.text.len());
        let skipped = self.text.get(self.pos..end).unwrap_or("");
        self.line += skipped.bytes().filter(|&b| b == b'\n').count();
        self.pos = end;
    }

    fn err(&self, line: usize, message: impl Into<String>) -> IoError {
        IoError::Malformed {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    fn truncated(&self, expected: &str) -> IoError {
        IoError::Truncated {
            path: self.path.to_path_buf(),
            line: self.line,
            expected: expected.to_string(),
        }
    }

    /// Skips past `end`, or fails with "truncated".
    fn skip_past(&mut self, end: &str, what: &str) -> Result<(), IoError> {
        match self.rest().find(end) {
            Some(k) => {
                self.advance(k + end.len());
                Ok(())
            }
            None => Err(self.truncated(what)),
        }
    }

    fn skip_ws(&mut self) {
        let n = self.rest().len() - self.rest().trim_start().len();
        self.advance(n);
    }

    fn name(&mut self) -> Result<String, IoError> {
        let r = self.rest();
        let n = r
            .find(|c: char| c.is_whitespace() || matches!(c, '/' | '>' | '=' | '<'))
            .unwrap_or(r.len());
        if n == 0 {
            return Err(if r.is_empty() {
                self.truncated("a tag or attribute name")
            } else {
                self.err(
                    self.line,
                    format!("expected a name, found {:?}", first_char(r)),
                )
            });
        }
        let s = r[..n].to_string();
        self.advance(n);
        Ok(s)
    }
}

fn first_char(s: &str) -> String {
    s.chars().next().map(String::from).unwrap_or_default()
}

/// Replaces entity and character references.
pub(crate) fn unescape(s: &str, line: usize, path: &Path) -> Result<String, IoError> {
    if !s.contains('&') {
        return Ok(s.to_string());
    }
    let bad = |m: String| IoError::Malformed {
        path: path.to_path_buf(),
        line,
        message: m,
    };
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(k) = rest.find('&') {
        out.push_str(&rest[..k]);
        rest = &rest[k..];
        let end = rest
            .find(';')
            .ok_or_else(|| bad("unterminated entity reference".into()))?;
        let ent = &rest[1..end];
        let c = match ent {
            "lt" => '<',
            "gt" => '>',
            "amp" => '&',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(h) = ent.strip_prefix("#x") {
                    u32::from_str_radix(h, 16).ok()
                } else if let Some(d) = ent.strip_prefix('#') {
                    d.parse::<u32>().ok()
                } else {
                    None
                };
                code.and_then(char::from_u32)
                    .ok_or_else(|| bad(format!("unknown entity reference &{ent};")))?
            }
        };
        out.push(c);
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Escapes text for an attribute value or character data.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// Parses a document and returns its root element.
pub(crate) fn parse(text: &str, path: &Path) -> Result<Element, IoError> {
    let mut c = Cursor {
        text,
        pos: 0,
        line: 1,
        path,
    };
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let r = c.rest();
        if r.is_empty() {
            break;
        }
        if r.starts_with("<?") {
            c.skip_past("?>", "the end of a processing instruction")?;
        } else if r.starts_with("<!--") {
            c.skip_past("-->", "the end of a comment")?;
        } else if r.starts_with("<![CDATA[") {
            return Err(IoError::Unsupported {
                path: path.to_path_buf(),
                line: c.line,
                what: "XML CDATA sections".into(),
            });
        } else if r.starts_with("<!") {
            c.skip_past(">", "the end of a declaration")?;
        } else if r.starts_with("</") {
            let line = c.line;
            c.advance(2);
            let name = c.name()?;
            c.skip_ws();
            if !c.rest().starts_with('>') {
                return Err(if c.rest().is_empty() {
                    c.truncated("'>'")
                } else {
                    c.err(c.line, format!("expected '>' after </{name}"))
                });
            }
            c.advance(1);
            let Some(e) = stack.pop() else {
                return Err(c.err(
                    line,
                    format!("closing tag </{name}> without an open element"),
                ));
            };
            if e.name != name {
                return Err(c.err(
                    line,
                    format!(
                        "closing tag </{name}> does not match <{}> (line {})",
                        e.name, e.line
                    ),
                ));
            }
            attach(e, &mut stack, &mut root, &c, line)?;
        } else if r.starts_with('<') {
            let line = c.line;
            c.advance(1);
            let name = c.name()?;
            let mut e = Element {
                name,
                attrs: Vec::new(),
                children: Vec::new(),
                text: String::new(),
                line,
                text_line: line,
            };
            let self_closing;
            loop {
                c.skip_ws();
                let r = c.rest();
                if r.starts_with("/>") {
                    c.advance(2);
                    self_closing = true;
                    break;
                }
                if r.starts_with('>') {
                    c.advance(1);
                    self_closing = false;
                    break;
                }
                if r.is_empty() {
                    return Err(c.truncated(&format!("the end of tag <{}>", e.name)));
                }
                let aline = c.line;
                let key = c.name()?;
                c.skip_ws();
                if !c.rest().starts_with('=') {
                    return Err(c.err(c.line, format!("attribute {key}: expected '='")));
                }
                c.advance(1);
                c.skip_ws();
                let q = match c.rest().chars().next() {
                    Some(q @ ('"' | '\'')) => q,
                    Some(_) => {
                        return Err(c.err(c.line, format!("attribute {key}: expected a quote")))
                    }
                    None => return Err(c.truncated("an attribute value")),
                };
                c.advance(1);
                let r = c.rest();
                let Some(k) = r.find(q) else {
                    return Err(c.truncated("the end of an attribute value"));
                };
                let raw = &r[..k];
                if raw.contains('<') {
                    return Err(c.err(aline, format!("attribute {key}: '<' in a value")));
                }
                let value = unescape(raw, aline, path)?;
                c.advance(k + 1);
                if e.attrs.iter().any(|(k2, _)| *k2 == key) {
                    return Err(c.err(aline, format!("attribute {key} given twice")));
                }
                e.attrs.push((key, value));
            }
            if stack.len() >= MAX_DEPTH {
                return Err(c.err(
                    line,
                    format!("elements nested deeper than {MAX_DEPTH} levels"),
                ));
            }
            if self_closing {
                attach(e, &mut stack, &mut root, &c, line)?;
            } else {
                stack.push(e);
            }
        } else {
            let line = c.line;
            let k = r.find('<').unwrap_or(r.len());
            let raw = &r[..k];
            match stack.last_mut() {
                Some(top) => {
                    if top.text.is_empty() {
                        top.text_line = line;
                    }
                    top.text.push_str(&unescape(raw, line, path)?);
                }
                None => {
                    if !raw.trim().is_empty() {
                        return Err(c.err(line, "text outside the root element"));
                    }
                }
            }
            c.advance(k);
        }
    }
    if let Some(open) = stack.last() {
        return Err(c.truncated(&format!("</{}> (opened on line {})", open.name, open.line)));
    }
    root.ok_or_else(|| c.truncated("the root element"))
}

fn attach(
    e: Element,
    stack: &mut [Element],
    root: &mut Option<Element>,
    c: &Cursor<'_>,
    line: usize,
) -> Result<(), IoError> {
    match stack.last_mut() {
        Some(parent) => parent.children.push(e),
        None => {
            if root.is_some() {
                return Err(c.err(line, "a second root element"));
            }
            *root = Some(e);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_elements_attributes_text_and_lines() {
        let t = "<?xml version=\"1.0\"?>\n<!-- c -->\n<A x='1' y=\"a&amp;b\">\n <B/>\n <C>\n 1 2\n</C></A>\n";
        let e = parse(t, Path::new("t")).unwrap();
        assert_eq!(e.name, "A");
        assert_eq!(e.line, 3);
        assert_eq!(e.attr("y"), Some("a&b"));
        assert_eq!(e.children.len(), 2);
        let c = e.child("C").unwrap();
        assert_eq!(c.line, 5);
        assert_eq!(c.text_line, 5);
        assert_eq!(c.text.trim(), "1 2");
    }

    #[test]
    fn errors_are_typed() {
        for (t, line) in [
            ("<A><B></A>", 1),
            ("<A>\n</B>", 2),
            ("<A x=1/>", 1),
            ("<A/><B/>", 1),
            ("\n\n<A x='&bogus;'/>", 3),
            ("x<A/>", 1),
        ] {
            let e = parse(t, Path::new("t")).unwrap_err();
            assert_eq!(e.line(), Some(line), "{t:?}: {e}");
        }
        let deep = "<a>".repeat(10_000);
        assert!(parse(&deep, Path::new("t")).is_err());
        assert!(parse("", Path::new("t")).is_err());
        assert_eq!(escape("<&\"'>"), "&lt;&amp;&quot;&apos;&gt;");
    }
}
