//! `nesy serve`: a folder of runs over HTTP, read-only, on the loopback address by default,
//! and nothing outside the folder, however the path is spelled.

use std::io::{BufRead as _, BufReader, Read as _, Write as _};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

use crate::common;

/// The server, stopped when dropped.
struct Server {
    child: Child,
    address: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `nesy serve DIR --port 0 extra…` and reads the address it announces.
fn start(dir: &std::path::Path, extra: &[&str]) -> (Server, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_nesy"))
        .arg("serve")
        .arg(dir)
        .args(["--port", "0"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting nesy serve");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let address = line
        .split("http://")
        .nth(1)
        .and_then(|rest| rest.split('/').next())
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .to_owned();
    (Server { child, address }, line)
}

/// Sends `request` as written and returns the whole response.
fn send(server: &Server, request: &str) -> String {
    let mut stream = TcpStream::connect(&server.address).unwrap();
    stream.write_all(request.as_bytes()).unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    response
}

/// Sends `GET target` as written (no client-side normalisation) and returns the status code
/// and body.
fn get(server: &Server, target: &str) -> (u16, String) {
    let response = send(
        server,
        &format!("GET {target} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"),
    );
    let code = response
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    let body = response
        .split_once("\r\n\r\n")
        .map(|(_, b)| b.to_owned())
        .unwrap_or_default();
    (code, body)
}

#[test]
fn the_runs_folder_is_served_read_only_on_loopback_and_nothing_outside_it() {
    let scratch = common::scratch();
    let runs = scratch.path().join("runs");
    std::fs::create_dir_all(runs.join("adapt/one")).unwrap();
    std::fs::write(runs.join("adapt/one/report.html"), "<p>one</p>").unwrap();
    std::fs::write(scratch.path().join("secret.txt"), "outside").unwrap();
    std::os::unix::fs::symlink(scratch.path().join("secret.txt"), runs.join("leak.txt")).unwrap();
    std::os::unix::fs::symlink(scratch.path(), runs.join("up")).unwrap();

    let (server, announced) = start(&runs, &[]);
    assert!(server.address.starts_with("127.0.0.1:"), "{announced}");

    let (code, index) = get(&server, "/");
    assert_eq!(code, 200);
    assert!(
        index.contains("<a href=\"adapt/one/report.html\">adapt/one</a>"),
        "{index}"
    );
    assert_eq!(
        get(&server, "/adapt/one/report.html"),
        (200, "<p>one</p>".to_owned())
    );

    for target in [
        "/../secret.txt",
        "/adapt/../../secret.txt",
        "/%2e%2e/secret.txt",
        "/%2E%2E%2Fsecret.txt",
        "/adapt/%2e%2e%2f%2e%2e%2fsecret.txt",
        "/leak.txt",
        "/up/secret.txt",
    ] {
        let (code, body) = get(&server, target);
        assert_eq!(code, 403, "{target}: {body}");
        assert!(body.contains("is outside the served folder"), "{target}: {body}");
        assert!(
            !body.contains("outside\n") && !body.contains("outside</"),
            "{target} leaked: {body}"
        );
    }
    assert_eq!(get(&server, "/nothing.html").0, 404);

    // Only reading: any other method is refused.
    let response = send(
        &server,
        "PUT /adapt/one/report.html HTTP/1.1\r\nContent-Length: 1\r\n\r\nx",
    );
    assert!(response.starts_with("HTTP/1.1 405"), "{response}");
    assert_eq!(
        std::fs::read_to_string(runs.join("adapt/one/report.html")).unwrap(),
        "<p>one</p>"
    );
}

#[test]
fn serving_a_missing_folder_is_refused_by_name() {
    let (code, _, stderr) = common::run(&["serve", "/nonexistent/runs", "--port", "0"]);
    assert_eq!(code, Some(2));
    assert!(stderr.contains("/nonexistent/runs"), "{stderr}");
}
