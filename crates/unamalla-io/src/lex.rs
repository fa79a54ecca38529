//! A whitespace tokenizer with 1-based line numbers, shared by the text readers of this crate.

use std::path::{Path, PathBuf};

use crate::error::IoError;

/// Upper bound for capacities taken from counts in a file (a lying count must not make a
/// reader allocate gigabytes before the data runs out).
pub(crate) const MAX_PREALLOC: usize = 1 << 20;

/// Splits text into whitespace-separated tokens, remembering the line of each.
pub(crate) struct Lexer<'a> {
    path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    cur: std::str::SplitWhitespace<'a>,
    /// 1-based number of the line `cur` comes from (0 before the first line).
    line: usize,
    /// Added to every line number (for text that starts inside a larger file).
    line_offset: usize,
    peeked: Option<(&'a str, usize)>,
    /// Everything from this character to the end of a line is ignored.
    comment: Option<char>,
}

impl<'a> Lexer<'a> {
    /// A lexer over `text`, whose first line is line 1 of `path`.
    pub(crate) fn new(text: &'a str, path: &'a Path) -> Self {
        Self::starting_at(text, path, 1)
    }

    /// A lexer over `text`, whose first line is line `first_line` of `path`.
    pub(crate) fn starting_at(text: &'a str, path: &'a Path, first_line: usize) -> Self {
        Self {
            path,
            lines: text.lines().enumerate(),
            cur: "".split_whitespace(),
            line: 0,
            line_offset: first_line.saturating_sub(1),
            peeked: None,
            comment: None,
        }
    }

    /// Ignores everything from `c` to the end of each line.
    pub(crate) fn with_comments(mut self, c: char) -> Self {
        self.comment = Some(c);
        self
    }

    pub(crate) fn pb(&self) -> PathBuf {
        self.path.to_path_buf()
    }

    /// The 1-based number of the line last read (at least 1).
    pub(crate) fn line(&self) -> usize {
        (self.line + self.line_offset).max(1)
    }

    fn strip(&self, l: &'a str) -> &'a str {
        match self.comment {
            Some(c) => l.split(c).next().unwrap_or(""),
            None => l,
        }
    }

    /// The next whole line, discarding whatever is left of the current one; `None` at the
    /// end. Used for free-text header lines (titles, file names).
    pub(crate) fn next_line(&mut self) -> Option<(&'a str, usize)> {
        self.peeked = None;
        let (k, l) = self.lines.next()?;
        self.line = k + 1;
        self.cur = "".split_whitespace();
        Some((l, self.line()))
    }

    /// The file the text comes from (for error values built outside the lexer).
    pub(crate) fn path(&self) -> &'a Path {
        self.path
    }

    /// The next token without consuming it.
    pub(crate) fn peek(&mut self) -> Option<(&'a str, usize)> {
        if self.peeked.is_none() {
            self.peeked = self.next();
        }
        self.peeked
    }

    /// Drops the rest of the current line and everything up to and including the next blank
    /// line (VTK 5 `METADATA` blocks end with a blank line).
    pub(crate) fn skip_block_to_blank_line(&mut self) {
        self.peeked = None;
        self.cur = "".split_whitespace();
        for (k, l) in self.lines.by_ref() {
            self.line = k + 1;
            if l.trim().is_empty() {
                break;
            }
        }
    }

    pub(crate) fn next(&mut self) -> Option<(&'a str, usize)> {
        if let Some(t) = self.peeked.take() {
            return Some(t);
        }
        loop {
            if let Some(t) = self.cur.next() {
                return Some((t, self.line()));
            }
            let (k, l) = self.lines.next()?;
            self.line = k + 1;
            self.cur = self.strip(l).split_whitespace();
        }
    }

    pub(crate) fn token(&mut self, expected: &str) -> Result<(&'a str, usize), IoError> {
        self.next().ok_or_else(|| IoError::Truncated {
            path: self.pb(),
            line: self.line(),
            expected: expected.to_string(),
        })
    }

    pub(crate) fn malformed(&self, line: usize, message: String) -> IoError {
        IoError::Malformed {
            path: self.pb(),
            line,
            message,
        }
    }

    pub(crate) fn keyword(&mut self, kw: &str) -> Result<usize, IoError> {
        let (t, line) = self.token(kw)?;
        if t.eq_ignore_ascii_case(kw) {
            Ok(line)
        } else {
            Err(self.malformed(line, format!("expected {kw}, found {t:?}")))
        }
    }

    pub(crate) fn usize(&mut self, what: &str) -> Result<(usize, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<usize>().map(|v| (v, line)).map_err(|_| {
            self.malformed(
                line,
                format!("{what}: expected a non-negative integer, found {t:?}"),
            )
        })
    }

    pub(crate) fn i64(&mut self, what: &str) -> Result<(i64, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<i64>()
            .map(|v| (v, line))
            .map_err(|_| self.malformed(line, format!("{what}: expected an integer, found {t:?}")))
    }

    /// A finite number (Fortran `D` exponents are accepted).
    pub(crate) fn f64(&mut self, what: &str) -> Result<(f64, usize), IoError> {
        let (t, line) = self.token(what)?;
        parse_f64(t)
            .filter(|v| v.is_finite())
            .map(|v| (v, line))
            .ok_or_else(|| {
                self.malformed(
                    line,
                    format!("{what}: expected a finite number, found {t:?}"),
                )
            })
    }

    /// Any number of Rust's `f64` grammar, `nan` and `inf` included (data arrays of VTK files
    /// may hold them; the readers check coordinates themselves), unlike [`f64`](Self::f64).
    pub(crate) fn number(&mut self, what: &str) -> Result<(f64, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<f64>()
            .map(|v| (v, line))
            .map_err(|_| self.malformed(line, format!("{what}: expected a number, found {t:?}")))
    }

    /// Reads `count` values with [`number`](Self::number).
    pub(crate) fn numbers(&mut self, count: usize, what: &str) -> Result<Vec<f64>, IoError> {
        let mut v = Vec::with_capacity(count.min(MAX_PREALLOC));
        for _ in 0..count {
            v.push(self.number(what)?.0);
        }
        Ok(v)
    }

    /// `a * b` or a "count too large" error.
    pub(crate) fn mul(
        &self,
        a: usize,
        b: usize,
        line: usize,
        what: &str,
    ) -> Result<usize, IoError> {
        a.checked_mul(b)
            .ok_or_else(|| self.malformed(line, format!("{what}: count too large")))
    }

    /// Fails unless only whitespace (and comments) remain.
    pub(crate) fn expect_end(&mut self, what: &str) -> Result<(), IoError> {
        match self.next() {
            None => Ok(()),
            Some((t, line)) => {
                Err(self.malformed(line, format!("unexpected {t:?} after the end of {what}")))
            }
        }
    }
}

/// Parses a number, accepting Fortran's `D`/`d` exponent marker too (`1.5D+02`).
pub(crate) fn parse_f64(t: &str) -> Option<f64> {
    match t.parse::<f64>() {
        Ok(v) => Some(v),
        Err(_) if t.contains(['d', 'D']) => t.replace(['d', 'D'], "e").parse().ok(),
        Err(_) => None,
    }
}
