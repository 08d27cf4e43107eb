//! # nesy-input
//!
//! Every file nesy reads on a user's behalf (scenes, policies, plans, demos, cassettes,
//! configurations, manifests) comes through here. A path that names a directory, a device
//! (`/dev/zero`) or a named pipe is refused before it is opened, so a read can neither run
//! until memory is gone nor block for ever; a regular file larger than the cap its kind
//! allows is refused with its size and the cap. The errors are [`std::io::Error`]s of kind
//! [`std::io::ErrorKind::InvalidInput`], so each reader keeps its own typed error (which
//! names the file) around them.
//!
//! ```
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("scene.json");
//! std::fs::write(&path, "{}").unwrap();
//! assert_eq!(nesy_input::read_text(&path, nesy_input::MAX_JSON_BYTES).unwrap(), "{}");
//! let err = nesy_input::read_text(std::path::Path::new("/dev/zero"), 1024).unwrap_err();
//! assert!(err.to_string().contains("not a regular file"));
//! ```

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// Cap for a policy's Python source. Generated policies are a few kilobytes.
pub const MAX_POLICY_BYTES: u64 = 1 << 20;
/// Cap for JSON, TOML and plan text inputs: scenes, targets, scenario files, manifests,
/// configurations, PDDL and plans.
pub const MAX_JSON_BYTES: u64 = 64 << 20;
/// Cap for one image of a demonstration folder.
pub const MAX_IMAGE_BYTES: u64 = 64 << 20;
/// Cap for a cassette file (its images live in separate blobs).
pub const MAX_CASSETTE_BYTES: u64 = 1 << 30;
/// Cap for an MCAP demonstration (a 90-keyframe demo with 384² views is about 9 MB).
pub const MAX_DEMO_BYTES: u64 = 4 << 30;

/// The whole of a regular file of at most `max_bytes`.
pub fn read_bytes(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    // Checked on the path before opening: opening a FIFO for reading blocks until a writer
    // comes.
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "a device, pipe or socket"
        };
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("the path is not a regular file ({what})"),
        ));
    }
    let too_big = |size: u64| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("the file is {size} bytes, more than the {max_bytes} allowed for it"),
        )
    };
    if meta.len() > max_bytes {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // `take` bounds a file that grows while it is read.
    File::open(path)?.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The whole of a regular UTF-8 text file of at most `max_bytes`. A leading byte-order mark
/// is dropped (editors on some systems write one). Invalid UTF-8 is an
/// [`io::ErrorKind::InvalidData`] error giving the byte offset.
pub fn read_text(path: &Path, max_bytes: u64) -> io::Result<String> {
    let bytes = read_bytes(path, max_bytes)?;
    let text = String::from_utf8(bytes).map_err(|err| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text: invalid byte at offset {}",
                err.utf8_error().valid_up_to()
            ),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_under_the_cap_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        std::fs::write(&path, "\u{feff}hello").unwrap();
        assert_eq!(read_text(&path, 5 + 3).unwrap(), "hello");
        assert_eq!(read_bytes(&path, 8).unwrap().len(), 8);
    }

    #[test]
    fn oversized_files_are_refused_with_their_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.txt");
        std::fs::write(&path, vec![b'x'; 100]).unwrap();
        let err = read_bytes(&path, 99).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("100 bytes, more than the 99"), "{err}");
    }

    #[test]
    fn devices_directories_and_pipes_are_refused_unopened() {
        let dir = tempfile::tempdir().unwrap();
        for path in [Path::new("/dev/zero"), dir.path()] {
            let err = read_bytes(path, MAX_JSON_BYTES).unwrap_err();
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
        let pipe = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&pipe).status().unwrap();
        assert!(made.success());
        // Would block for ever if it were opened.
        let err = read_text(&pipe, MAX_JSON_BYTES).unwrap_err();
        assert!(err.to_string().contains("a device, pipe or socket"), "{err}");
    }

    #[test]
    fn invalid_utf8_names_the_offset() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.py");
        std::fs::write(&path, b"abc\xffdef").unwrap();
        let err = read_text(&path, 100).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidData);
        assert!(err.to_string().contains("offset 3"), "{err}");
    }
}
