//! Files in and out: input text read with a size limit and located errors (line, column,
//! field); output written completely or not at all.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// An output file written completely or not at all: the content goes to a temporary file
/// beside `path` (`.NAME.tmp-PID.EXT`, the extension kept last for encoders that choose the
/// format by it), renamed over `path` by [`PendingFile::commit`]. Dropped uncommitted (an
/// error, an interrupt), the temporary file is removed and `path` is left as it was.
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
        fs::File::create(&self.tmp)
    }

    /// Flushes the temporary file to disk and renames it over the final path.
    pub fn commit(mut self) -> io::Result<()> {
        fs::File::open(&self.tmp)?.sync_all()?;
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
