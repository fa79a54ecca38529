//! The token reader of the legacy format: whitespace-separated tokens over lines, with
//! 1-based line numbers for the errors.

use std::path::{Path, PathBuf};

use crate::error::IoError;

/// Upper bound for capacities taken from counts in the file (a lying count must not make us
/// allocate gigabytes before the data runs out).
pub(super) const MAX_PREALLOC: usize = 1 << 20;

pub(super) struct Lexer<'a> {
    pub(super) path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    cur: std::str::SplitWhitespace<'a>,
    /// 1-based number of the line `cur` comes from (0 before the first line).
    pub(super) line: usize,
    peeked: Option<(&'a str, usize)>,
}

impl<'a> Lexer<'a> {
    pub(super) fn new(text: &'a str, path: &'a Path) -> Self {
        Self {
            path,
            lines: text.lines().enumerate(),
            cur: "".split_whitespace(),
            line: 0,
            peeked: None,
        }
    }

    pub(super) fn pb(&self) -> PathBuf {
        self.path.to_path_buf()
    }

    /// The next whole line (used for the header only, before any token was read).
    pub(super) fn raw_line(&mut self) -> Option<(&'a str, usize)> {
        let (k, l) = self.lines.next()?;
        self.line = k + 1;
        Some((l, k + 1))
    }

    pub(super) fn next(&mut self) -> Option<(&'a str, usize)> {
        if let Some(t) = self.peeked.take() {
            return Some(t);
        }
        loop {
            if let Some(t) = self.cur.next() {
                return Some((t, self.line));
            }
            let (k, l) = self.lines.next()?;
            self.line = k + 1;
            self.cur = l.split_whitespace();
        }
    }

    pub(super) fn peek(&mut self) -> Option<(&'a str, usize)> {
        if self.peeked.is_none() {
            self.peeked = self.next();
        }
        self.peeked
    }

    /// Drops the rest of the current line and everything up to and including the next blank
    /// line (VTK 5 `METADATA` blocks end with a blank line).
    pub(super) fn skip_block_to_blank_line(&mut self) {
        self.peeked = None;
        self.cur = "".split_whitespace();
        for (k, l) in self.lines.by_ref() {
            self.line = k + 1;
            if l.trim().is_empty() {
                break;
            }
        }
    }

    pub(super) fn token(&mut self, expected: &str) -> Result<(&'a str, usize), IoError> {
        self.next().ok_or_else(|| IoError::Truncated {
            path: self.pb(),
            line: self.line.max(1),
            expected: expected.to_string(),
        })
    }

    pub(super) fn malformed(&self, line: usize, message: String) -> IoError {
        IoError::Malformed {
            path: self.pb(),
            line,
            message,
        }
    }

    pub(super) fn keyword(&mut self, kw: &str) -> Result<usize, IoError> {
        let (t, line) = self.token(kw)?;
        if t.eq_ignore_ascii_case(kw) {
            Ok(line)
        } else {
            Err(self.malformed(line, format!("expected {kw}, found {t:?}")))
        }
    }

    pub(super) fn usize(&mut self, what: &str) -> Result<(usize, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<usize>().map(|v| (v, line)).map_err(|_| {
            self.malformed(
                line,
                format!("{what}: expected a non-negative integer, found {t:?}"),
            )
        })
    }

    pub(super) fn f64(&mut self, what: &str) -> Result<(f64, usize), IoError> {
        let (t, line) = self.token(what)?;
        t.parse::<f64>()
            .map(|v| (v, line))
            .map_err(|_| self.malformed(line, format!("{what}: expected a number, found {t:?}")))
    }

    /// Reads `count` numbers.
    pub(super) fn numbers(&mut self, count: usize, what: &str) -> Result<Vec<f64>, IoError> {
        let mut v = Vec::with_capacity(count.min(MAX_PREALLOC));
        for _ in 0..count {
            v.push(self.f64(what)?.0);
        }
        Ok(v)
    }

    /// `a * b` or a "count too large" error.
    pub(super) fn mul(
        &self,
        a: usize,
        b: usize,
        line: usize,
        what: &str,
    ) -> Result<usize, IoError> {
        a.checked_mul(b)
            .ok_or_else(|| self.malformed(line, format!("{what}: count too large")))
    }
}
