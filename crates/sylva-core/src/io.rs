//! Files in and out: input text read with a size limit and located errors (line, column,
//! field); output written completely or not at all.

use std::fs;
use std::io::{self, Write};
use std::path::Path;

/// Writes a file atomically: the content goes to a temporary file beside `path`, which is
/// renamed over `path` only once it is complete. On any error the temporary file is removed
/// and `path` is left as it was.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name =
        path.file_name().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "output path has no file name"))?;
    let tmp = dir.join(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id()));
    let result = (|| {
        let file = fs::File::create(&tmp)?;
        let mut w = io::BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Largest preset or grammar file read, bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Reads a text file of at most [`MAX_FILE_BYTES`].
pub fn read_text(path: &Path) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "file is {} bytes, larger than the {} byte limit for presets and grammars",
            meta.len(),
            MAX_FILE_BYTES
        ));
    }
    std::fs::read_to_string(path).map_err(|e| e.to_string())
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
pub fn field_line(text: &str, field: &str) -> usize {
    let (found, table_line) = find_field(text, field);
    found.unwrap_or(table_line)
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
    let key = key.split('[').next().unwrap_or(key);
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
