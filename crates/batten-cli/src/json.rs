//! The layout of the JSON the commands write: serde_json's pretty layout (two spaces an
//! indent, one member a line), except that an array of numbers, strings, booleans or nulls
//! runs on as text does, wrapped near [`WRAP_COLUMN`]. A fair's report lists the indices of
//! its moved points: one a line, a 10⁶-point fair wrote 12 MB, 7.9 of them indentation and
//! line breaks; run on, it writes 7 MB, and a pair such as the end tangent angles reads on one
//! line.

use std::io::{self, Write};

use serde::Serialize;
use serde_json::ser::{CharEscape, CompactFormatter, Formatter};

/// The column after which an array of scalars goes on on the next line.
const WRAP_COLUMN: usize = 96;

/// `value` as JSON in the layout above.
///
/// # Errors
/// serde_json's, for a value it cannot encode (a map with non-string keys).
pub fn pretty<T: Serialize + ?Sized>(value: &T) -> serde_json::Result<String> {
    let mut out = Vec::with_capacity(4096);
    let mut ser = serde_json::Serializer::with_formatter(&mut out, Layout::default());
    value.serialize(&mut ser)?;
    // serde_json writes only UTF-8 (its strings are Rust strings, escaped).
    String::from_utf8(out).map_err(|e| serde_json::Error::io(io::Error::other(e)))
}

/// One open array: whether an element has been an object or an array (then every element
/// goes on a line of its own, as in the pretty layout).
#[derive(Debug, Default)]
struct Array {
    nested: bool,
}

/// The formatter of [`pretty`].
#[derive(Debug, Default)]
struct Layout {
    depth: usize,
    arrays: Vec<Array>,
    /// An array element has begun and nothing of it is written yet: the break or space
    /// before it waits for what it is. `Some(first)`.
    pending: Option<bool>,
    /// Whether the object being written has a member.
    has_member: Vec<bool>,
    /// The length of the line being written.
    column: usize,
    /// A scalar's text before it is written (one buffer for all of them).
    buffer: Vec<u8>,
}

impl Layout {
    fn newline<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b"\n")?;
        for _ in 0..self.depth {
            w.write_all(b"  ")?;
        }
        self.column = 2 * self.depth;
        Ok(())
    }

    /// Before an object or an array as an array's element: its own line.
    fn before_nested<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        if self.pending.take().is_some() {
            if let Some(a) = self.arrays.last_mut() {
                a.nested = true;
            }
            self.newline(w)?;
        }
        Ok(())
    }

    /// Before a scalar as an array's element: nothing for the first, then a space, or a line
    /// break past the wrap column.
    fn before_scalar<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        match self.pending.take() {
            Some(true) => {}
            Some(false) if self.column >= WRAP_COLUMN => self.newline(w)?,
            Some(false) => {
                w.write_all(b" ")?;
                self.column += 1;
            }
            None => {}
        }
        Ok(())
    }

    /// Write `text` (no line break in it), counting the column.
    fn text<W: ?Sized + Write>(&mut self, w: &mut W, text: &[u8]) -> io::Result<()> {
        self.column += text.len();
        w.write_all(text)
    }

    /// A scalar, written by serde_json's compact formatter into `buffer` first, then out.
    fn scalar<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        write: impl FnOnce(&mut CompactFormatter, &mut Vec<u8>) -> io::Result<()>,
    ) -> io::Result<()> {
        self.before_scalar(w)?;
        let mut buffer = std::mem::take(&mut self.buffer);
        buffer.clear();
        write(&mut CompactFormatter, &mut buffer)?;
        let written = self.text(w, &buffer);
        self.buffer = buffer;
        written
    }
}

impl Formatter for Layout {
    fn write_null<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_null(b))
    }

    fn write_bool<W: ?Sized + Write>(&mut self, w: &mut W, v: bool) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_bool(b, v))
    }

    fn write_i64<W: ?Sized + Write>(&mut self, w: &mut W, v: i64) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_i64(b, v))
    }

    fn write_i128<W: ?Sized + Write>(&mut self, w: &mut W, v: i128) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_i128(b, v))
    }

    fn write_u64<W: ?Sized + Write>(&mut self, w: &mut W, v: u64) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_u64(b, v))
    }

    fn write_u128<W: ?Sized + Write>(&mut self, w: &mut W, v: u128) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_u128(b, v))
    }

    fn write_f32<W: ?Sized + Write>(&mut self, w: &mut W, v: f32) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_f32(b, v))
    }

    fn write_f64<W: ?Sized + Write>(&mut self, w: &mut W, v: f64) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_f64(b, v))
    }

    fn write_number_str<W: ?Sized + Write>(&mut self, w: &mut W, v: &str) -> io::Result<()> {
        self.scalar(w, |f, b| f.write_number_str(b, v))
    }

    fn begin_string<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_scalar(w)?;
        self.text(w, b"\"")
    }

    fn end_string<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.text(w, b"\"")
    }

    fn write_string_fragment<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        fragment: &str,
    ) -> io::Result<()> {
        self.text(w, fragment.as_bytes())
    }

    fn write_char_escape<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        escape: CharEscape,
    ) -> io::Result<()> {
        let mut buffer = Vec::with_capacity(6);
        CompactFormatter.write_char_escape(&mut buffer, escape)?;
        self.text(w, &buffer)
    }

    fn write_raw_fragment<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        fragment: &str,
    ) -> io::Result<()> {
        self.before_scalar(w)?;
        self.text(w, fragment.as_bytes())
    }

    fn begin_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_nested(w)?;
        self.depth += 1;
        self.arrays.push(Array::default());
        self.text(w, b"[")
    }

    fn end_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.depth -= 1;
        if self.arrays.pop().is_some_and(|a| a.nested) {
            self.newline(w)?;
        }
        self.text(w, b"]")
    }

    fn begin_array_value<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        if !first {
            self.text(w, b",")?;
        }
        self.pending = Some(first);
        Ok(())
    }

    fn end_array_value<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }

    fn begin_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.before_nested(w)?;
        self.depth += 1;
        self.has_member.push(false);
        self.text(w, b"{")
    }

    fn end_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.depth -= 1;
        if self.has_member.pop().unwrap_or(false) {
            self.newline(w)?;
        }
        self.text(w, b"}")
    }

    fn begin_object_key<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        if !first {
            self.text(w, b",")?;
        }
        if let Some(m) = self.has_member.last_mut() {
            *m = true;
        }
        self.newline(w)
    }

    fn end_object_key<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }

    fn begin_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.text(w, b": ")
    }

    fn end_object_value<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn objects_as_pretty_scalar_arrays_run_on() {
        let v = json!({
            "name": "a \"quoted\" name",
            "empty": [],
            "none": {},
            "pair": [1.5, -2],
            "rows": [{"a": 1, "b": [true, null]}, {"a": 2}],
            "nested": [[1, 2], [3]],
        });
        let text = pretty(&v).expect("encodes");
        let want = "{\n  \"empty\": [],\n  \"name\": \"a \\\"quoted\\\" name\",\n  \"nested\": [\n    \
                    [1, 2],\n    [3]\n  ],\n  \"none\": {},\n  \"pair\": [1.5, -2],\n  \"rows\": [\n    \
                    {\n      \"a\": 1,\n      \"b\": [true, null]\n    },\n    {\n      \"a\": 2\n    \
                    }\n  ]\n}";
        assert_eq!(text, want);
        let back: serde_json::Value = serde_json::from_str(&text).expect("parses");
        assert_eq!(back, v);
    }

    #[test]
    fn long_scalar_arrays_wrap_near_the_column() {
        let v = json!({ "moved": (0..1000).collect::<Vec<u32>>() });
        let text = pretty(&v).expect("encodes");
        assert!(text.lines().count() > 10);
        for line in text.lines() {
            assert!(line.len() <= WRAP_COLUMN + 8, "{line}");
        }
        let back: serde_json::Value = serde_json::from_str(&text).expect("parses");
        assert_eq!(back, v);
    }
}
