//! Seeded mutations of a TOML file for the loaders' harnesses (the world's and the launch
//! file's): a numeric value replaced by an impossible or edge value, a key deleted, a table
//! duplicated, the text truncated. Each mutant says what was done, where, and whether the value
//! put in is impossible for its key (the caller's `Oracle` decides that).

use harvey_geometry::Rng;

/// What replaces a number: every one is impossible for some key, the first five for all keys
/// except an unsigned integer that takes any value (a seed).
pub const VALUES: [&str; 8] = ["inf", "-inf", "nan", "1e308", "-1e308", "0", "-1", "9223372036854775807"];

/// One number of the file: its line (1-based), byte range, key and the table it sits in.
#[derive(Debug, Clone)]
pub struct Number {
    pub line: usize,
    pub start: usize,
    pub end: usize,
    pub key: String,
    pub table: String,
}

/// What a mutation did.
#[derive(Debug, Clone)]
pub enum Change {
    /// `number`'s text replaced by `value`.
    Number {
        number: Number,
        value: &'static str,
    },
    DeleteKey {
        _line: usize,
    },
    DuplicateTable {
        _line: usize,
    },
    Truncate {
        _at: usize,
    },
}

/// Byte offset of the first `#` outside a string on `line`, or its length.
fn comment_start(line: &str) -> usize {
    let mut quoted = false;
    for (i, b) in line.bytes().enumerate() {
        match b {
            b'"' => quoted = !quoted,
            b'#' if !quoted => return i,
            _ => {}
        }
    }
    line.len()
}

/// Every number outside strings and comments, with its key and table.
pub fn numbers(text: &str) -> Vec<Number> {
    let (mut out, mut table, mut key, mut offset) = (Vec::new(), String::new(), String::new(), 0);
    let mut depth = 0i64; // open brackets of a multi-line value
    for (n, line) in text.split_inclusive('\n').enumerate() {
        let code = &line[..comment_start(line)];
        let trimmed = code.trim();
        let mut value_from = 0;
        let header = depth == 0 && trimmed.starts_with('[') && !trimmed.contains('=');
        if !header {
            depth += brackets(code);
        }
        if header {
            table = trimmed.trim_matches(|c| c == '[' || c == ']').to_owned();
        } else if let Some(eq) = code.find('=').filter(|&eq| !code[..eq].contains('"')) {
            key = code[..eq].trim().to_owned();
            value_from = eq + 1;
        }
        let bytes = code.as_bytes();
        let (mut i, mut quoted) = (0, false);
        while i < bytes.len() {
            let b = bytes[i];
            if b == b'"' {
                quoted = !quoted;
            }
            let prev_ok =
                i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || b"_.-\"".contains(&bytes[i - 1]));
            let starts =
                b.is_ascii_digit() || (b == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
            if !quoted && i >= value_from && prev_ok && starts {
                let mut j = i + 1;
                while j < bytes.len()
                    && (bytes[j].is_ascii_digit()
                        || b"._eE".contains(&bytes[j])
                        || (b"+-".contains(&bytes[j]) && b"eE".contains(&bytes[j - 1])))
                {
                    j += 1;
                }
                out.push(Number {
                    line: n + 1,
                    start: offset + i,
                    end: offset + j,
                    key: key.clone(),
                    table: table.clone(),
                });
                i = j;
                continue;
            }
            i += 1;
        }
        offset += line.len();
    }
    out
}

/// Opened minus closed brackets outside strings.
fn brackets(code: &str) -> i64 {
    let (mut depth, mut quoted) = (0, false);
    for b in code.bytes() {
        match b {
            b'"' => quoted = !quoted,
            b'[' if !quoted => depth += 1,
            b']' if !quoted => depth -= 1,
            _ => {}
        }
    }
    depth
}

/// Lines that hold a whole `key = value` (brackets balanced), as byte ranges.
fn key_lines(text: &str) -> Vec<(usize, usize, usize)> {
    let (mut out, mut offset) = (Vec::new(), 0);
    for (n, line) in text.split_inclusive('\n').enumerate() {
        let code = &line[..comment_start(line)];
        if code.contains('=') && !code.trim_start().starts_with('[') && brackets(code) == 0 {
            out.push((n + 1, offset, offset + line.len()));
        }
        offset += line.len();
    }
    out
}

/// Table headers with the byte range of their table (to the next header or the end).
fn tables(text: &str) -> Vec<(usize, usize, usize)> {
    let (mut starts, mut offset, mut depth) = (Vec::new(), 0, 0);
    for (n, line) in text.split_inclusive('\n').enumerate() {
        let code = &line[..comment_start(line)];
        if depth == 0 && code.trim_start().starts_with('[') && !code.contains('=') {
            starts.push((n + 1, offset));
        } else {
            depth += brackets(code);
        }
        offset += line.len();
    }
    let ends: Vec<usize> = starts.iter().skip(1).map(|s| s.1).chain([text.len()]).collect();
    starts.into_iter().zip(ends).map(|((n, s), e)| (n, s, e)).collect()
}

fn pick<T: Clone>(rng: &mut Rng, items: &[T]) -> Option<T> {
    (!items.is_empty()).then(|| items[(rng.next_u64() % items.len() as u64) as usize].clone())
}

/// One seeded mutant of `text`: mostly numbers (six in ten), else a key deleted, a table
/// duplicated or the text cut short.
pub fn mutate(text: &str, rng: &mut Rng) -> (String, Change) {
    let choice = rng.next_u64() % 10;
    if choice < 6
        && let Some(number) = pick(rng, &numbers(text))
    {
        let value = VALUES[(rng.next_u64() % VALUES.len() as u64) as usize];
        let out = format!("{}{value}{}", &text[..number.start], &text[number.end..]);
        return (out, Change::Number { number, value });
    }
    if choice < 8
        && let Some((line, s, e)) = pick(rng, &key_lines(text))
    {
        return (format!("{}{}", &text[..s], &text[e..]), Change::DeleteKey { _line: line });
    }
    if choice < 9
        && let Some((line, s, e)) = pick(rng, &tables(text))
    {
        return (format!("{text}\n{}", &text[s..e]), Change::DuplicateTable { _line: line });
    }
    let mut at = (rng.next_u64() % text.len().max(1) as u64) as usize;
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    (text[..at].to_owned(), Change::Truncate { _at: at })
}

/// The key's last part (`x_m` of `start.x_m`).
pub fn leaf(key: &str) -> &str {
    key.rsplit('.').next().unwrap_or(key)
}

/// Whether `err` names `file` and the mutated number's line or key.
pub fn names_place(err: &str, file: &str, number: &Number) -> bool {
    err.contains(file) && (err.contains(&format!(":{}:", number.line)) || err.contains(leaf(&number.key)))
}

/// The values impossible for every bounded key: non-finite, beyond 1e300, or a huge integer.
pub fn always_impossible(value: &str) -> bool {
    !matches!(value, "0" | "-1")
}

#[test]
fn numbers_are_found_outside_strings_and_comments() {
    let text = "a = 1 # 2\n[t]\nb = [[-0.5, 2e-3], [1, 2]]\nc = \"--x 5\"\nd = [\n  [7],\n]\n";
    let found: Vec<(usize, String, String)> =
        numbers(text).into_iter().map(|n| (n.line, text[n.start..n.end].to_owned(), n.key)).collect();
    let want =
        [(1, "1", "a"), (3, "-0.5", "b"), (3, "2e-3", "b"), (3, "1", "b"), (3, "2", "b"), (6, "7", "d")];
    let want: Vec<(usize, String, String)> =
        want.iter().map(|(l, v, k)| (*l, (*v).to_owned(), (*k).to_owned())).collect();
    assert_eq!(found, want);
    assert_eq!(numbers(text)[1].table, "t");
}
