//! The path of the JSON value at a position of a file's text (e.g. `modes[1].quality_factor`),
//! so that a parse error (`invalid type`, `unknown field`, a number out of range) names the
//! field it is in, not only its line and column.

/// One open container while scanning: an object with the key last read, or an array with the
/// index of the current element.
enum Frame {
    Object(Option<String>),
    Array(usize),
}

/// The path of the value being read at `line` and `column` (1-based, as `serde_json` reports
/// them) of `text`: keys joined by `.`, array indices as `[i]`; empty at the top level.
pub(crate) fn path_at(text: &str, line: usize, column: usize) -> String {
    let offset = offset_of(text, line, column);
    let mut stack: Vec<Frame> = Vec::new();
    let mut chars = text.char_indices().peekable();
    // Whether the string just read is an object key (followed by `:`).
    let mut expecting_key = false;
    while let Some((index, c)) = chars.next() {
        if index >= offset {
            break;
        }
        match c {
            '{' => {
                stack.push(Frame::Object(None));
                expecting_key = true;
            }
            '[' => stack.push(Frame::Array(0)),
            '}' | ']' => {
                stack.pop();
                expecting_key = false;
            }
            ',' => match stack.last_mut() {
                Some(Frame::Array(i)) => *i += 1,
                Some(Frame::Object(key)) => {
                    *key = None;
                    expecting_key = true;
                }
                None => {}
            },
            '"' => {
                let mut string = String::new();
                let mut escaped = false;
                for (_, s) in chars.by_ref() {
                    if escaped {
                        string.push(s);
                        escaped = false;
                    } else if s == '\\' {
                        escaped = true;
                    } else if s == '"' {
                        break;
                    } else {
                        string.push(s);
                    }
                }
                if expecting_key {
                    if let Some(Frame::Object(key)) = stack.last_mut() {
                        *key = Some(string);
                    }
                    expecting_key = false;
                }
            }
            _ => {}
        }
    }
    let mut path = String::new();
    for frame in &stack {
        match frame {
            Frame::Object(Some(key)) => {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(key);
            }
            Frame::Object(None) => {}
            Frame::Array(i) => path.push_str(&format!("[{i}]")),
        }
    }
    path
}

/// The byte offset of `line`, `column` (1-based; column counts bytes) in `text`, clamped to
/// its length.
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut offset = 0;
    for (number, content) in text.split_inclusive('\n').enumerate() {
        if number + 1 == line {
            return (offset + column).min(text.len());
        }
        offset += content.len();
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::path_at;

    #[test]
    fn names_the_field_of_an_error_position() {
        let text = "{\"name\": \"x\",\n \"modes\": [{\"a\": 1}, {\"quality_factor\": \"q\"}]}";
        // serde_json reports the end of the bad value `"q"` on line 2.
        let column = text.lines().nth(1).unwrap().find("\"q\"").unwrap() + 3;
        assert_eq!(path_at(text, 2, column), "modes[1].quality_factor");
        assert_eq!(path_at(text, 1, 12), "name");
        let error =
            serde_json::from_str::<serde_json::Value>("{\"a\": [1, 2, x]}").expect_err("syntax");
        assert_eq!(
            path_at("{\"a\": [1, 2, x]}", error.line(), error.column()),
            "a[2]"
        );
    }
}
