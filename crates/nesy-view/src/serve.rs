//! A read-only HTTP server over one folder of runs, for people who keep their runs on a
//! remote machine and forward a port. It answers `GET` and `HEAD` with the files under the
//! folder and a listing for each directory; nothing it serves lies outside the folder, whether
//! asked with `..`, with `..` percent-encoded, or through a symbolic link, and such a request
//! gets a 403 that says why.

use std::path::{Component, Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, SystemTime};

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

use crate::html::{Html, Page};

/// The file a run directory's page is in; a directory holding one is listed as a run.
pub const REPORT_FILE: &str = "report.html";

/// How deep under the folder the index looks for run reports (`runs/adapt/NAME/` is 3).
const INDEX_DEPTH: usize = 4;
/// The most a request's head may take; a longer one is refused.
const MAX_HEAD_BYTES: usize = 16 * 1024;
/// How long a client may take to send its request's head.
const HEAD_TIMEOUT: Duration = Duration::from_secs(10);

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The folder to serve is missing or not a directory.
    #[error("{path}: {message}")]
    Folder {
        /// The folder as given.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
}

/// Why a request gets no file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Refusal {
    /// The path leads outside the served folder (by `..`, encoded or not, or a symbolic link).
    #[error("{path} is outside the served folder")]
    Outside {
        /// The requested path, decoded.
        path: String,
    },
    /// Nothing is there.
    #[error("{path}: no such file or directory")]
    NotFound {
        /// The requested path, decoded.
        path: String,
    },
    /// The path is not one: a bad percent-escape, bytes that are not UTF-8, or a NUL.
    #[error("{path}: not a valid path ({why})")]
    Malformed {
        /// The requested path, as sent.
        path: String,
        /// What is wrong.
        why: &'static str,
    },
}

/// What a request's path names inside the folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Resolved {
    /// A regular file (symbolic links followed, still inside the folder).
    File(PathBuf),
    /// A directory.
    Directory(PathBuf),
}

/// The folder being served, held by its canonical path.
#[derive(Debug, Clone)]
pub struct Folder {
    root: PathBuf,
}

impl Folder {
    /// The folder at `path`, which must exist and be a directory.
    pub fn open(path: &Path) -> Result<Folder, ServeError> {
        let error = |message: String| ServeError::Folder {
            path: path.to_owned(),
            message,
        };
        let root = path.canonicalize().map_err(|e| error(e.to_string()))?;
        if !root.is_dir() {
            return Err(error("not a directory".into()));
        }
        Ok(Folder { root })
    }

    /// The folder's canonical path.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// What the request target `target` (`/runs/a/report.html?x`, percent-encoded) names.
    ///
    /// ```
    /// let dir = tempfile::tempdir().unwrap();
    /// std::fs::write(dir.path().join("report.html"), "<p>hi</p>").unwrap();
    /// let folder = nesy_view::Folder::open(dir.path()).unwrap();
    /// assert!(matches!(folder.resolve("/report.html"), Ok(nesy_view::Resolved::File(_))));
    /// assert!(matches!(folder.resolve("/%2e%2e/etc/passwd"), Err(nesy_view::Refusal::Outside { .. })));
    /// ```
    pub fn resolve(&self, target: &str) -> Result<Resolved, Refusal> {
        let raw = target.split(['?', '#']).next().unwrap_or_default();
        let decoded = percent_decode(raw).map_err(|why| Refusal::Malformed {
            path: raw.to_owned(),
            why,
        })?;
        let mut path = self.root.clone();
        for segment in decoded.split('/') {
            match segment {
                "" | "." => {}
                ".." => return Err(Refusal::Outside { path: decoded }),
                _ => {
                    // A segment is one name: `Path::join` would let an absolute one replace
                    // the whole path.
                    let mut components = Path::new(segment).components();
                    if !matches!(
                        (components.next(), components.next()),
                        (Some(Component::Normal(_)), None)
                    ) {
                        return Err(Refusal::Outside { path: decoded });
                    }
                    path.push(segment);
                }
            }
        }
        let real = match path.canonicalize() {
            Ok(real) => real,
            // A link out of the folder whose far end is missing is still a way out.
            Err(_) if std::fs::symlink_metadata(&path).is_ok_and(|m| m.file_type().is_symlink()) => {
                return Err(Refusal::Outside { path: decoded });
            }
            Err(_) => return Err(Refusal::NotFound { path: decoded }),
        };
        if !real.starts_with(&self.root) {
            return Err(Refusal::Outside { path: decoded });
        }
        if real.is_dir() {
            Ok(Resolved::Directory(real))
        } else if real.is_file() {
            Ok(Resolved::File(real))
        } else {
            // Devices and pipes are never served.
            Err(Refusal::NotFound { path: decoded })
        }
    }
}

/// Serves `folder` on `listener` until the task is dropped: each connection on its own task,
/// one request per connection.
pub async fn serve(listener: TcpListener, folder: Folder) -> std::io::Result<()> {
    let folder = Arc::new(folder);
    loop {
        let (stream, peer) = listener.accept().await?;
        let folder = folder.clone();
        tokio::spawn(async move {
            if let Err(e) = answer(stream, &folder).await {
                tracing::debug!("{peer}: {e}");
            }
        });
    }
}

/// Reads one request and answers it.
async fn answer(mut stream: TcpStream, folder: &Folder) -> std::io::Result<()> {
    let head = match tokio::time::timeout(HEAD_TIMEOUT, read_head(&mut stream)).await {
        Ok(Ok(Some(head))) => head,
        Ok(Ok(None)) => {
            return respond_text(
                &mut stream,
                400,
                "Bad Request",
                "the request's head is too long or incomplete\n",
                true,
            )
            .await;
        }
        Ok(Err(e)) => return Err(e),
        Err(_) => return Ok(()),
    };
    let mut parts = head.lines().next().unwrap_or_default().split(' ');
    let (method, target) = (parts.next().unwrap_or_default(), parts.next().unwrap_or_default());
    let with_body = method != "HEAD";
    if method != "GET" && method != "HEAD" {
        return respond_text(
            &mut stream,
            405,
            "Method Not Allowed",
            "nesy serve is read-only: GET and HEAD only\n",
            with_body,
        )
        .await;
    }
    tracing::info!("{method} {target}");
    match folder.resolve(target) {
        Ok(Resolved::File(path)) => respond_file(&mut stream, &path, with_body).await,
        Ok(Resolved::Directory(dir)) => {
            let raw = target.split(['?', '#']).next().unwrap_or("/");
            if !raw.ends_with('/') {
                // Relative links in the listing and in a report need the trailing slash.
                let location = format!("{raw}/");
                let head = format!(
                    "HTTP/1.1 301 Moved Permanently\r\nLocation: {location}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
                );
                return stream.write_all(head.as_bytes()).await;
            }
            let page = listing(folder, &dir);
            respond(
                &mut stream,
                200,
                "OK",
                "text/html; charset=utf-8",
                page.as_bytes(),
                with_body,
            )
            .await
        }
        Err(refusal @ Refusal::Outside { .. }) => {
            let text = format!(
                "nesy serve: {refusal} ({}); nothing outside it is served\n",
                folder.root.display()
            );
            respond_text(&mut stream, 403, "Forbidden", &text, with_body).await
        }
        Err(refusal @ Refusal::NotFound { .. }) => {
            respond_text(
                &mut stream,
                404,
                "Not Found",
                &format!("nesy serve: {refusal}\n"),
                with_body,
            )
            .await
        }
        Err(refusal @ Refusal::Malformed { .. }) => {
            respond_text(
                &mut stream,
                400,
                "Bad Request",
                &format!("nesy serve: {refusal}\n"),
                with_body,
            )
            .await
        }
    }
}

/// The request's head (up to the blank line), or `None` when it is too long or the client
/// stopped sending before it ended.
async fn read_head(stream: &mut TcpStream) -> std::io::Result<Option<String>> {
    let mut head = Vec::new();
    let mut buffer = [0u8; 2048];
    loop {
        let n = stream.read(&mut buffer).await?;
        if n == 0 {
            return Ok(None);
        }
        head.extend_from_slice(&buffer[..n]);
        if let Some(end) = head.windows(4).position(|w| w == b"\r\n\r\n") {
            head.truncate(end);
            return Ok(Some(String::from_utf8_lossy(&head).into_owned()));
        }
        if head.len() > MAX_HEAD_BYTES {
            return Ok(None);
        }
    }
}

async fn respond_text(
    stream: &mut TcpStream,
    code: u16,
    reason: &str,
    text: &str,
    with_body: bool,
) -> std::io::Result<()> {
    respond(
        stream,
        code,
        reason,
        "text/plain; charset=utf-8",
        text.as_bytes(),
        with_body,
    )
    .await
}

async fn respond(
    stream: &mut TcpStream,
    code: u16,
    reason: &str,
    content_type: &str,
    body: &[u8],
    with_body: bool,
) -> std::io::Result<()> {
    let head = format!(
        "HTTP/1.1 {code} {reason}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nX-Content-Type-Options: nosniff\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes()).await?;
    if with_body {
        stream.write_all(body).await?;
    }
    stream.flush().await
}

/// Sends a file, streamed rather than read whole: a recording can be large.
async fn respond_file(stream: &mut TcpStream, path: &Path, with_body: bool) -> std::io::Result<()> {
    let mut file = match tokio::fs::File::open(path).await {
        Ok(file) => file,
        Err(e) => {
            let text = format!("nesy serve: {}: {e}\n", path.display());
            return respond_text(stream, 500, "Internal Server Error", &text, with_body).await;
        }
    };
    let length = file.metadata().await?.len();
    let head = format!(
        "HTTP/1.1 200 OK\r\nContent-Type: {}\r\nContent-Length: {length}\r\nX-Content-Type-Options: nosniff\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        content_type(path)
    );
    stream.write_all(head.as_bytes()).await?;
    if with_body {
        tokio::io::copy(&mut file, stream).await?;
    }
    stream.flush().await
}

/// The media type a browser needs to show a run's files.
fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).unwrap_or_default() {
        "html" => "text/html; charset=utf-8",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "mp4" => "video/mp4",
        "json" | "jsonl" => "application/json",
        "md" | "txt" | "py" | "csv" | "log" | "pddl" | "jinja" | "toml" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

/// A directory's page: the run reports under it (a few levels down), then its entries.
fn listing(folder: &Folder, dir: &Path) -> String {
    let relative = dir.strip_prefix(&folder.root).unwrap_or(Path::new(""));
    let shown = format!("/{}", relative.display());
    let mut page = Page::new(&format!("nesy serve: {shown}"));
    page.push(Html::tag(
        "p",
        "muted",
        Html::text(&format!(
            "Read-only view of {}. Reports open in this browser; every other file downloads or shows as text.",
            folder.root.display()
        )),
    ));
    let mut reports = Vec::new();
    find_reports(dir, dir, INDEX_DEPTH, &mut reports);
    reports.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    if !reports.is_empty() {
        let rows = reports.iter().map(|(run, modified)| {
            let href = format!("{}/{REPORT_FILE}", run.display());
            vec![
                Html::link(&href, &run.display().to_string()),
                Html::text(&format_age(*modified)),
            ]
        });
        page.section("reports", "Run reports", Html::table(&["run", "written"], rows));
    }
    let mut entries: Vec<(String, bool)> = std::fs::read_dir(dir)
        .map(|read| {
            read.filter_map(Result::ok)
                .map(|entry| {
                    let name = entry.file_name().to_string_lossy().into_owned();
                    (name, entry.path().is_dir())
                })
                .collect()
        })
        .unwrap_or_default();
    entries.sort();
    let mut items = Vec::new();
    if !relative.as_os_str().is_empty() {
        items.push(Html::link("../", "../"));
    }
    for (name, is_dir) in entries {
        let shown = if is_dir { format!("{name}/") } else { name };
        items.push(Html::link(&shown, &shown));
    }
    page.section("files", "Files here", Html::list(items));
    page.finish()
}

/// Directories under `dir` (at most `depth` levels) that hold a report, relative to `base`,
/// with when the report was written. Symbolic links are not followed here.
fn find_reports(base: &Path, dir: &Path, depth: usize, out: &mut Vec<(PathBuf, Option<SystemTime>)>) {
    if depth == 0 {
        return;
    }
    let Ok(read) = std::fs::read_dir(dir) else { return };
    for entry in read.filter_map(Result::ok) {
        let Ok(kind) = entry.file_type() else { continue };
        if !kind.is_dir() {
            continue;
        }
        let path = entry.path();
        let report = path.join(REPORT_FILE);
        if report.is_file() {
            let modified = report.metadata().and_then(|m| m.modified()).ok();
            out.push((path.strip_prefix(base).unwrap_or(&path).to_owned(), modified));
        }
        find_reports(base, &path, depth - 1, out);
    }
}

/// How long ago a file was written, in the largest whole unit.
fn format_age(modified: Option<SystemTime>) -> String {
    let Some(age) = modified.and_then(|m| SystemTime::now().duration_since(m).ok()) else {
        return "-".into();
    };
    let s = age.as_secs();
    match s {
        0..60 => format!("{s} s ago"),
        60..3600 => format!("{} min ago", s / 60),
        3600..86400 => format!("{} h ago", s / 3600),
        _ => format!("{} days ago", s / 86400),
    }
}

/// `%XX` escapes decoded; the result must be UTF-8 without NUL.
fn percent_decode(raw: &str) -> Result<String, &'static str> {
    let bytes = raw.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .ok_or("a % not followed by two hex digits")?;
            let text = std::str::from_utf8(hex).map_err(|_| "a % not followed by two hex digits")?;
            let byte = u8::from_str_radix(text, 16).map_err(|_| "a % not followed by two hex digits")?;
            out.push(byte);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    if out.contains(&0) {
        return Err("a NUL byte");
    }
    String::from_utf8(out).map_err(|_| "not UTF-8 once decoded")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder() -> (tempfile::TempDir, Folder) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("runs/a")).unwrap();
        std::fs::write(dir.path().join("runs/a/report.html"), "<p>a</p>").unwrap();
        let folder = Folder::open(&dir.path().join("runs")).unwrap();
        (dir, folder)
    }

    #[test]
    fn files_and_directories_inside_are_found() {
        let (_dir, folder) = folder();
        assert_eq!(
            folder.resolve("/a/report.html?x=1"),
            Ok(Resolved::File(folder.root().join("a/report.html")))
        );
        assert_eq!(
            folder.resolve("/a/"),
            Ok(Resolved::Directory(folder.root().join("a")))
        );
        assert_eq!(
            folder.resolve("/"),
            Ok(Resolved::Directory(folder.root().to_owned()))
        );
        assert!(matches!(
            folder.resolve("/nothing"),
            Err(Refusal::NotFound { .. })
        ));
    }

    #[test]
    fn dot_dot_plain_or_encoded_is_refused() {
        let (_dir, folder) = folder();
        for target in [
            "/../secret",
            "/a/../../secret",
            "/%2e%2e/secret",
            "/%2E%2E%2Fsecret",
            "/a/%2e%2e/%2e%2e/secret",
            "/..%2f..%2fetc%2fpasswd",
        ] {
            assert!(
                matches!(folder.resolve(target), Err(Refusal::Outside { .. })),
                "{target}: {:?}",
                folder.resolve(target)
            );
        }
        // An inner `..` that would stay inside is refused as well: no path is normalised.
        assert!(matches!(
            folder.resolve("/a/../a/report.html"),
            Err(Refusal::Outside { .. })
        ));
    }

    #[test]
    fn malformed_escapes_and_nul_are_refused() {
        let (_dir, folder) = folder();
        assert!(matches!(folder.resolve("/a%2"), Err(Refusal::Malformed { .. })));
        assert!(matches!(folder.resolve("/a%zz"), Err(Refusal::Malformed { .. })));
        assert!(matches!(folder.resolve("/a%00b"), Err(Refusal::Malformed { .. })));
        assert!(matches!(folder.resolve("/%ff"), Err(Refusal::Malformed { .. })));
    }

    #[cfg(unix)]
    #[test]
    fn symbolic_links_out_of_the_folder_are_refused_and_inside_followed() {
        let (dir, folder) = folder();
        std::fs::write(dir.path().join("secret.txt"), "no").unwrap();
        let runs = dir.path().join("runs");
        std::os::unix::fs::symlink(dir.path().join("secret.txt"), runs.join("leak.txt")).unwrap();
        std::os::unix::fs::symlink(dir.path(), runs.join("up")).unwrap();
        std::os::unix::fs::symlink(dir.path().join("missing"), runs.join("dangling")).unwrap();
        std::os::unix::fs::symlink(runs.join("a"), runs.join("alias")).unwrap();
        for target in ["/leak.txt", "/up/secret.txt", "/up/", "/dangling"] {
            assert!(
                matches!(folder.resolve(target), Err(Refusal::Outside { .. })),
                "{target}: {:?}",
                folder.resolve(target)
            );
        }
        assert_eq!(
            folder.resolve("/alias/report.html"),
            Ok(Resolved::File(folder.root().join("a/report.html")))
        );
    }

    #[test]
    fn the_index_lists_reports_below_it() {
        let (_dir, folder) = folder();
        let page = listing(&folder, folder.root());
        assert!(page.contains("<a href=\"a/report.html\">a</a>"), "{page}");
        assert!(page.contains("<a href=\"a/\">a/</a>"), "{page}");
    }

    #[test]
    fn a_missing_folder_is_an_error_naming_it() {
        let error = Folder::open(Path::new("/nonexistent/runs")).unwrap_err();
        assert!(error.to_string().starts_with("/nonexistent/runs: "), "{error}");
    }
}
