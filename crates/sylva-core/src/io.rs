//! Files in and out: input text read with a size limit and located errors (line, column,
//! field); output written completely or not at all.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// Temporary paths of every [`PendingFile`] alive in the process, so that a signal handler
/// can remove them before the process exits ([`abandon_pending`]).
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Set by [`abandon_pending`]: no temporary file may be created from then on.
static ABANDONED: AtomicBool = AtomicBool::new(false);

fn pending() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every pending temporary file (and directory) of the process and refuses new ones:
/// what a signal handler calls just before the process exits, so that an interrupt leaves
/// neither a temporary file nor a partial output under a final name. Returns how many paths
/// were removed.
pub fn abandon_pending() -> usize {
    ABANDONED.store(true, Ordering::SeqCst);
    let list = pending();
    let mut removed = 0;
    for p in list.iter() {
        let gone = if p.is_dir() { fs::remove_dir_all(p) } else { fs::remove_file(p) };
        removed += usize::from(gone.is_ok());
    }
    removed
}

/// Forgets a temporary path (its owner removed or committed it).
fn deregister(tmp: &Path) {
    let mut list = pending();
    if let Some(i) = list.iter().rposition(|p| p == tmp) {
        list.swap_remove(i);
    }
}

fn refuse_if_abandoned(tmp: &Path) -> io::Result<()> {
    if ABANDONED.load(Ordering::SeqCst) {
        let _ = if tmp.is_dir() { fs::remove_dir_all(tmp) } else { fs::remove_file(tmp) };
        return Err(io::Error::new(io::ErrorKind::Interrupted, "interrupted: no output is written"));
    }
    Ok(())
}

/// An output file written completely or not at all: the content goes to a temporary file
/// beside `path` (`.NAME.tmp-PID.EXT`, the extension kept last for encoders that choose the
/// format by it), renamed over `path` by [`PendingFile::commit`]. Dropped uncommitted (an
/// error, an interrupt), the temporary file is removed and `path` is left as it was. While
/// it lives, its temporary path is registered for [`abandon_pending`].
#[derive(Debug)]
pub struct PendingFile {
    tmp: PathBuf,
    path: PathBuf,
    done: bool,
}

impl PendingFile {
    /// A pending file for `path` (nothing is created yet: write [`Self::tmp`]).
    pub fn new(path: &Path) -> io::Result<Self> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let name = path
            .file_name()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "output path has no file name"))?
            .to_string_lossy();
        let tmp = match path.extension() {
            Some(ext) => dir.join(format!(".{name}.tmp-{}.{}", std::process::id(), ext.to_string_lossy())),
            None => dir.join(format!(".{name}.tmp-{}", std::process::id())),
        };
        refuse_if_abandoned(&tmp)?;
        pending().push(tmp.clone());
        Ok(Self { tmp, path: path.to_path_buf(), done: false })
    }

    /// Where the content goes until it is committed.
    pub fn tmp(&self) -> &Path {
        &self.tmp
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Creates the temporary file for writing.
    pub fn create(&self) -> io::Result<fs::File> {
        let f = fs::File::create(&self.tmp)?;
        refuse_if_abandoned(&self.tmp)?;
        Ok(f)
    }

    /// Flushes the temporary file to disk and renames it over the final path. An empty
    /// temporary file is refused: every format Sylva writes has content, and a write that
    /// failed silently (a full disk under an encoder that drops its errors) leaves one.
    pub fn commit(mut self) -> io::Result<()> {
        let f = fs::File::open(&self.tmp)?;
        if f.metadata()?.len() == 0 {
            return Err(io::Error::other(format!("{} came out empty; nothing was written", self.tmp.display())));
        }
        f.sync_all()?;
        refuse_if_abandoned(&self.tmp)?;
        fs::rename(&self.tmp, &self.path)?;
        self.done = true;
        Ok(())
    }
}

impl Drop for PendingFile {
    fn drop(&mut self) {
        if !self.done {
            let _ = fs::remove_file(&self.tmp);
        }
        deregister(&self.tmp);
    }
}

/// A set of output files (a render's frames) written together or not at all: they go to a
/// temporary directory (`PARENT/.NAME.tmp-PID`), moved into the final directory by
/// [`PendingDir::commit`]. Dropped uncommitted, the temporary directory is removed. While it
/// lives, it is registered for [`abandon_pending`].
#[derive(Debug)]
pub struct PendingDir {
    tmp: PathBuf,
    done: bool,
}

impl PendingDir {
    /// Creates the temporary directory `.NAME.tmp-PID` in `parent`.
    pub fn new(parent: &Path, name: &str) -> io::Result<Self> {
        let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
        refuse_if_abandoned(&tmp)?;
        pending().push(tmp.clone());
        let dir = Self { tmp, done: false };
        fs::create_dir_all(&dir.tmp)?;
        refuse_if_abandoned(&dir.tmp)?;
        Ok(dir)
    }

    /// Where the files go until they are committed.
    pub fn tmp(&self) -> &Path {
        &self.tmp
    }

    /// Moves every file into `dir` (created when missing), after removing the files of `dir`
    /// that `stale` names (an earlier run's), then removes the temporary directory. Returns
    /// the number of files moved.
    pub fn commit(mut self, dir: &Path, stale: impl Fn(&str) -> bool) -> io::Result<usize> {
        fs::create_dir_all(dir)?;
        for e in fs::read_dir(dir)? {
            let e = e?;
            if e.file_type()?.is_file() && stale(&e.file_name().to_string_lossy()) {
                fs::remove_file(e.path())?;
            }
        }
        let mut moved = 0;
        for e in fs::read_dir(&self.tmp)? {
            let e = e?;
            refuse_if_abandoned(&self.tmp)?;
            fs::rename(e.path(), dir.join(e.file_name()))?;
            moved += 1;
        }
        fs::remove_dir(&self.tmp)?;
        self.done = true;
        Ok(moved)
    }
}

impl Drop for PendingDir {
    fn drop(&mut self) {
        if !self.done {
            let _ = fs::remove_dir_all(&self.tmp);
        }
        deregister(&self.tmp);
    }
}

/// Writes a file atomically ([`PendingFile`]): `fill` writes the content; on any error the
/// temporary file is removed and `path` is left as it was.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let pending = PendingFile::new(path)?;
    let mut w = io::BufWriter::new(pending.create()?);
    fill(&mut w)?;
    w.into_inner().map_err(|e| e.into_error())?;
    pending.commit()
}

/// Largest preset or grammar file read, bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Reads a text file of at most [`MAX_FILE_BYTES`]. The limit holds for what is read, not
/// what the file system reports, so devices and pipes (`/dev/zero`, `/dev/stdin`) stop at it
/// too. Bad UTF-8 is reported with its line and column.
pub fn read_text(path: &Path) -> Result<String, String> {
    let too_large = |what: String| {
        format!("file is {what}, larger than the {MAX_FILE_BYTES} byte limit for presets, grammars, scenes and winds")
    };
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if meta.is_dir() {
        return Err("is a directory, expected a text file".into());
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_large(format!("{} bytes", meta.len())));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| io::Read::read_to_end(&mut io::Read::take(f, MAX_FILE_BYTES + 1), &mut bytes))
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(format!("more than {MAX_FILE_BYTES} bytes")));
    }
    String::from_utf8(bytes).map_err(|e| {
        let good = e.utf8_error().valid_up_to();
        let text = std::str::from_utf8(&e.as_bytes()[..good]).unwrap_or_default();
        let (line, col) = line_col(text, good);
        format!("line {line}, column {col}: invalid UTF-8 (byte {good}); expected UTF-8 text")
    })
}

/// Longest run of the input quoted back in an error message, characters.
pub const MAX_QUOTE: usize = 60;

/// A TOML parse error as Sylva reports it: 1-based line and column, and the message with
/// every quoted token cut to [`MAX_QUOTE`] characters, long digit runs (a float written out
/// in full) shortened to scientific notation, and the key named where the parser's message
/// names none (`duplicate key`, `invalid type`).
pub fn toml_error(text: &str, e: &toml::de::Error) -> (usize, usize, String) {
    let mut start = e.span().map_or(0, |s| s.start.min(text.len()));
    let mut message = shorten(e.message().trim());
    // A tagged table (`[[field]]` with `kind = …`) is read whole before its fields, so an
    // error in one of its values is reported at the table's header: find the value.
    if text[start..].starts_with('[')
        && let Some(at) = locate_in_table(text, start, e.message())
    {
        start = at;
    }
    let (line, column) = line_col(text, start);
    // An untagged enum says only what it wanted.
    if let Some(wanted) = message.strip_prefix("wanted ") {
        let value = text[start..].split(['\n', ',', '}']).next().unwrap_or("").trim();
        message = format!("expected a {wanted}, found `{}`", cut(value));
    }
    let quotes_a_key = message.contains("field `") || message.contains("key `");
    const NAMELESS: [&str; 6] =
        ["duplicate key", "invalid type", "invalid value", "invalid length", "unknown variant", "expected a "];
    if !quotes_a_key
        && NAMELESS.iter().any(|m| message.starts_with(m))
        && let Some(key) = key_at(text, start)
    {
        message = format!("{message} (key `{}`)", cut(&key));
    }
    (line, column, message)
}

/// The byte offset of the value a parse error `message` is about, in the table whose header
/// starts at `header`: the value holding the token the message quotes (`-7`, `"a"`), or an
/// array of the length it found, or the first value of the type it found.
fn locate_in_table(text: &str, header: usize, message: &str) -> Option<usize> {
    let body = text[header..].find('\n').map_or(text.len(), |i| header + i + 1);
    let end = text[body..].find("\n[").map_or(text.len(), |i| body + i + 1);
    // (offset of the value, value) for every `key = value` line of the table.
    let mut values = Vec::new();
    let mut offset = body;
    for l in text[body..end].split_inclusive('\n') {
        if let Some(eq) = l.find('=') {
            let v = l[eq + 1..].split(" #").next().unwrap_or("").trim();
            let lead = l[eq + 1..].len() - l[eq + 1..].trim_start().len();
            values.push((offset + eq + 1 + lead, v));
        }
        offset += l.len();
    }
    let token = match (message.split('`').nth(1), message.split('"').nth(1)) {
        (Some(t), _) => Some(t.to_string()),
        (None, Some(t)) => Some(format!("\"{t}\"")),
        _ => None,
    };
    let standalone = |v: &str, t: &str| {
        v.match_indices(t).any(|(k, _)| {
            let before = v[..k].chars().next_back();
            let after = v[k + t.len()..].chars().next();
            let edge = |c: Option<char>| c.is_none_or(|c| !(c.is_alphanumeric() || c == '.' || c == '_'));
            edge(before) && edge(after)
        })
    };
    if let Some(t) = &token
        && let Some((at, _)) = values.iter().find(|(_, v)| standalone(v, t))
    {
        return Some(*at);
    }
    if let Some(n) = message.strip_prefix("invalid length ").and_then(|m| m.split(',').next()?.parse::<usize>().ok()) {
        let len = |v: &str| {
            v.strip_prefix('[')?.strip_suffix(']').map(|b| b.split(',').filter(|x| !x.trim().is_empty()).count())
        };
        if let Some((at, _)) = values.iter().find(|(_, v)| len(v) == Some(n)) {
            return Some(*at);
        }
    }
    let found = message.strip_prefix("invalid type: ")?.split(',').next()?;
    let looks = |v: &str| match found.split_whitespace().next().unwrap_or("") {
        "map" => v.starts_with('{'),
        "sequence" => v.starts_with('['),
        "string" => v.starts_with('"') || v.starts_with('\''),
        "boolean" => v == "true" || v == "false",
        "integer" | "floating" => v.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+'),
        _ => false,
    };
    values.iter().find(|(_, v)| looks(v)).map(|(at, _)| *at)
}

/// The key whose value (or which itself) starts at byte `at`: the name before the nearest
/// `=` before it on its line, or the name at `at` when it is the key.
fn key_at(text: &str, at: usize) -> Option<String> {
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..at];
    let is_key = |c: char| c.is_alphanumeric() || c == '_' || c == '-';
    let key = match before.trim_end().strip_suffix('=') {
        Some(k) => k.trim_end().rsplit(|c: char| !is_key(c)).next().unwrap_or(""),
        // Inside a value (an array's element) or at the key itself.
        None => match before.rfind('=') {
            Some(eq) if !before[eq..].contains(['{', ',']) || before[eq..].contains('[') => {
                before[..eq].trim_end().rsplit(|c: char| !is_key(c)).next().unwrap_or("")
            }
            _ => text[at..].split(|c: char| !is_key(c)).next().unwrap_or(""),
        },
    };
    (!key.is_empty()).then(|| key.to_string())
}

/// `s` cut to [`MAX_QUOTE`] characters, saying how long it was.
pub fn cut(s: &str) -> String {
    let n = s.chars().count();
    if n <= MAX_QUOTE {
        return s.to_string();
    }
    format!("{}… ({n} characters)", s.chars().take(MAX_QUOTE).collect::<String>())
}

/// Cuts each backquoted or double-quoted token of a message and shortens digit runs longer
/// than 17.
fn shorten(message: &str) -> String {
    let quoted = |message: &str, quote: char, inner: &dyn Fn(&str) -> String| {
        let mut out = String::new();
        let mut parts = message.split(quote);
        if let Some(first) = parts.next() {
            out.push_str(&inner(first));
        }
        for (k, part) in parts.enumerate() {
            out.push(quote);
            out.push_str(&if k % 2 == 0 { cut(&digits(part)) } else { inner(part) });
        }
        out
    };
    quoted(message, '`', &|outside: &str| quoted(outside, '"', &digits))
}

/// Digit runs longer than 17 (an f64 written out in full) as `d.ddde±N`.
fn digits(s: &str) -> String {
    let mut out = String::new();
    let chars: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if chars[i].is_ascii_digit() {
            let j = chars[i..].iter().position(|c| !c.is_ascii_digit()).map_or(chars.len(), |k| i + k);
            let run: String = chars[i..j].iter().collect();
            if run.len() > 17 {
                // A fraction `.000…` after a long integer part carries nothing.
                let mut end = j;
                if chars.get(j) == Some(&'.') {
                    end = chars[j + 1..].iter().position(|c| !c.is_ascii_digit()).map_or(chars.len(), |k| j + 1 + k);
                }
                let v: f64 = chars[i..end].iter().collect::<String>().parse().unwrap_or(f64::INFINITY);
                out.push_str(&format!("{v:.3e}"));
                i = end;
                continue;
            }
            out.push_str(&run);
            i = j;
            continue;
        }
        out.push(chars[i]);
        i += 1;
    }
    out
}

/// [`field_line`] for a path into a table value (`tree[0].params.frequency` set in an
/// inline table `params = { … }`): the line of the deepest part of the path that is set.
pub fn nested_field_line(text: &str, field: &str) -> usize {
    let mut path = field;
    loop {
        let (found, table_line) = find_field(text, path);
        if let Some(line) = found {
            return line;
        }
        match path.rsplit_once('.') {
            Some((head, _)) if head.contains('.') => path = head,
            _ => return table_line,
        }
    }
}

/// A fixed-size array read from TOML keeps its first elements and drops the rest without a
/// word: compares the text's arrays with the value read (`parsed`, serialised back) and
/// names the first whose length was not kept: (dotted path as [`field_line`] reads it,
/// length written, length read).
pub fn dropped_elements<T: serde::Serialize>(text: &str, parsed: &T) -> Option<(String, usize, usize)> {
    fn walk(raw: &toml::Table, read: &toml::Table, prefix: &str) -> Option<(String, usize, usize)> {
        raw.iter().find_map(|(key, v)| {
            let path = if prefix.is_empty() { key.clone() } else { format!("{prefix}.{key}") };
            match (v, read.get(key)?) {
                (toml::Value::Table(a), toml::Value::Table(b)) => walk(a, b, &path),
                (toml::Value::Array(a), toml::Value::Array(b)) if a.len() != b.len() => Some((path, a.len(), b.len())),
                (toml::Value::Array(a), toml::Value::Array(b)) => a
                    .iter()
                    .zip(b)
                    .enumerate()
                    .find_map(|(i, (x, y))| walk(x.as_table()?, y.as_table()?, &format!("{path}[{i}]"))),
                _ => None,
            }
        })
    }
    let raw = toml::from_str::<toml::Table>(text).ok()?;
    walk(&raw, &toml::Table::try_from(parsed).ok()?, "")
}

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map_or(before.len(), |i| before.len() - i - 1) + 1;
    (line, col)
}

/// Line where a dotted field is set in a TOML file: `name[i].key` in the i-th `[[name]]`
/// table (`level[1].length`), `name.key` in `[name]` (`wood.density`, `output.fps`), `key` at
/// the top. The line of the table when the key is absent; 1 when nothing matches (best
/// effort, for error messages).
///
/// A key that indexes an array of inline tables (`tree[0].copies[2].scale`,
/// `field[1].waves[0].speed`) finds that element's key, or the element.
pub fn field_line(text: &str, field: &str) -> usize {
    let (found, table_line) = find_field(text, field);
    match found {
        Some(line) => element_line(text, line, field).unwrap_or(line),
        // A whole table (`level` of `[[level]]` tables): its first header.
        None if !field.contains(['.', '[']) => text
            .lines()
            .position(|l| [format!("[[{field}]]"), format!("[{field}]")].iter().any(|h| l.trim_start().starts_with(h)))
            .map_or(table_line, |i| i + 1),
        None => table_line,
    }
}

/// For a path whose key is `name[k].sub`, set on 1-based `line` as `name = [ {…}, … ]`: the
/// line of `sub` inside the k-th inline table, or of that table.
fn element_line(text: &str, line: usize, field: &str) -> Option<usize> {
    let key = field.split_once('.').map_or(field, |(t, k)| if t.contains('[') { k } else { field });
    let (name, rest) = key.split_once('[')?;
    let (index, sub) = rest.split_once(']')?;
    let index: usize = index.parse().ok()?;
    let sub = sub.strip_prefix('.').unwrap_or(sub);
    let start = text.split_inclusive('\n').take(line - 1).map(str::len).sum::<usize>();
    let open = start + text[start..].find(name)? + name.len();
    let open = open + text[open..].find('[')? + 1;
    // Walk the array: depth 1 is its elements; a `{` at depth 1 opens one.
    let (mut depth, mut seen, mut in_string) = (1usize, 0usize, false);
    let mut element = None;
    for (i, ch) in text[open..].char_indices() {
        let at = open + i;
        match ch {
            '"' => in_string = !in_string,
            _ if in_string => {}
            '#' => {}
            '[' | '{' => {
                if ch == '{' && depth == 1 {
                    if seen == index {
                        element = Some(at);
                    }
                    seen += 1;
                }
                depth += 1;
            }
            ']' | '}' => {
                depth -= 1;
                if depth == 1
                    && let Some(element) = element
                {
                    let body = &text[element..at];
                    let found = (!sub.is_empty())
                        .then(|| {
                            body.match_indices(sub).find(|(k, _)| {
                                let before = body[..*k].chars().next_back();
                                let after = body[k + sub.len()..].trim_start();
                                before.is_none_or(|c| !(c.is_alphanumeric() || c == '_')) && after.starts_with('=')
                            })
                        })
                        .flatten()
                        .map_or(element, |(k, _)| element + k);
                    return Some(line_col(text, found).0);
                }
                if depth == 0 {
                    return None;
                }
            }
            _ => {}
        }
    }
    None
}

/// The line where `field` is set (`None` when absent) and the line of its table.
fn find_field(text: &str, field: &str) -> (Option<usize>, usize) {
    let (table, index, key) = match field.split_once('.') {
        Some((t, k)) => match t.split_once('[') {
            Some((name, rest)) => (format!("[[{name}]]"), rest.trim_end_matches(']').parse::<usize>().ok(), k),
            None => (format!("[{t}]"), None, k),
        },
        None => (String::new(), None, field),
    };
    let key = key.split(['[', '.']).next().unwrap_or(key);
    let mut in_table = table.is_empty();
    let mut seen = 0usize;
    let mut table_line = 1;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            in_table = false;
            if !table.is_empty() && t.starts_with(&table) {
                if index.is_none_or(|n| n == seen) {
                    in_table = true;
                    table_line = i + 1;
                }
                seen += 1;
            }
            continue;
        }
        if in_table && t.strip_prefix(key).is_some_and(|r| r.trim_start().starts_with('=')) {
            return (Some(i + 1), table_line);
        }
    }
    (None, table_line)
}
