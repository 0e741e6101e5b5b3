//! `gaitfit studio` as a server, without a browser: it listens on 127.0.0.1, serves the embedded
//! page, answers bad requests with the command line's words (and keeps serving), refuses a
//! request naming a non-loopback host, and its exports are what the library writes.
use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

struct Studio {
    child: Child,
    port: u16,
}

impl Drop for Studio {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn start() -> Studio {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_gaitfit"))
        .args(["studio", "--port", "0", "--fits"])
        .arg(root.join("fits"))
        .arg("--data")
        .arg(root.join("data"))
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start gaitfit studio");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut line)
        .expect("address line");
    let addr = line
        .split_whitespace()
        .find_map(|w| w.strip_prefix("http://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no 127.0.0.1 address in {line:?}"));
    let port = addr.trim_end_matches('/').parse().expect("port");
    Studio { child, port }
}

/// One HTTP/1.1 exchange; returns (status, headers, body).
fn http(port: u16, method: &str, path: &str, host: &str, body: &[u8]) -> (u16, String, Vec<u8>) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(120)))
        .expect("timeout");
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).expect("write");
    s.write_all(body).expect("write body");
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).expect("read");
    let split = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("end of headers");
    let headers = String::from_utf8_lossy(&raw[..split]).to_string();
    let status = headers
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status");
    let mut body = raw[split + 4..].to_vec();
    if headers
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked")
    {
        body = dechunk(&body);
    }
    (status, headers, body)
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let eol = b.windows(2).position(|w| w == b"\r\n").expect("chunk size");
        let n = usize::from_str_radix(String::from_utf8_lossy(&b[..eol]).trim(), 16).expect("hex");
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + n]);
        b = &b[eol + 4 + n..];
    }
}

fn post_json(st: &Studio, path: &str, body: &str) -> (u16, Value) {
    let host = format!("127.0.0.1:{}", st.port);
    let (status, _, b) = http(st.port, "POST", path, &host, body.as_bytes());
    let v = serde_json::from_slice(&b)
        .unwrap_or_else(|e| panic!("{path}: not JSON ({e}): {}", String::from_utf8_lossy(&b)));
    (status, v)
}

#[test]
fn serves_the_page_and_answers_bad_input_in_words() {
    let st = start();
    let host = format!("127.0.0.1:{}", st.port);
    let (status, headers, page) = http(st.port, "GET", "/", &host, b"");
    assert_eq!(status, 200);
    let page = String::from_utf8_lossy(&page);
    assert!(page.contains("gaitfit studio") && page.contains("/studio.js"));
    assert!(
        headers.contains("content-security-policy: default-src 'none'"),
        "{headers}"
    );
    // Nothing in the page refers to another host.
    for asset in ["/", "/studio.js", "/studio.css"] {
        let (_, _, b) = http(st.port, "GET", asset, &host, b"");
        let text = String::from_utf8_lossy(&b);
        assert!(
            !text.contains("http://") && !text.contains("https://"),
            "{asset} names another host"
        );
    }

    // A request naming another host (DNS rebinding) is refused.
    let (status, _, b) = http(st.port, "GET", "/api/catalog", "rebound.example", b"");
    assert_eq!(status, 403, "{}", String::from_utf8_lossy(&b));

    // Bad input: answered with the words the command line uses, and the server keeps serving.
    let cases = [
        ("not json", "not a studio request"),
        (r#"{"generator":"fly"}"#, "not a studio request"),
        (
            r#"{"generator":"run","values":{"speed_km_per_h":99},"changed":"speed_km_per_h"}"#,
            "parameter speed = 27.5: m/s must be within [0.3, 12] m/s",
        ),
        (
            r#"{"generator":"walk","values":{"speed_km_per_h":30},"changed":"speed_km_per_h"}"#,
            "above the anatomical limit sf_max = 182 steps/min",
        ),
        (
            r#"{"generator":"walk","values":{"attr.toe_clearance":1e300}}"#,
            "not a control",
        ),
        (r#"{"generator":"run","seconds":-1}"#, "duration -1 s"),
        (r#"{"generator":"run","fps":1e9}"#, "frame rate"),
        (
            r#"{"generator":"run","values":{"speed_km_per_h":12,"step_length_m":1.07,"step_freq_steps_per_min":187},"locks":["speed_km_per_h","step_length_m"],"changed":"step_freq_steps_per_min"}"#,
            "cannot all be fixed",
        ),
        (
            r#"{"generator":"walk","schedule":[{"step":400,"speed_km_per_h":4}]}"#,
            "past the walk's last step",
        ),
        (
            r#"{"generator":"run","schedule":[{"step":3,"speed_km_per_h":8},{"step":1,"speed_km_per_h":9}]}"#,
            "schedule",
        ),
        (r#"{"generator":"generalize","stop":true}"#, "no stop"),
        (
            r#"{"generator":"run","locks":["mass_kg"]}"#,
            "can be locked",
        ),
    ];
    for (body, expect) in cases {
        let (status, v) = post_json(&st, "/api/generate", body);
        assert_eq!(status, 200, "{body}: a refusal is an answer, not a failure");
        assert_eq!(v["ok"], Value::Bool(false), "{body}");
        let e = v["error"].as_str().unwrap_or("");
        assert!(e.contains(expect), "{body}: {e:?} should say {expect:?}");
    }
    let (status, v) = post_json(&st, "/api/generate", r#"{"generator":"walk","seconds":2}"#);
    assert_eq!(status, 200);
    assert_eq!(v["ok"], Value::Bool(true), "{v}");

    // The walk–run transition: walked, with KLAW's note.
    let (_, v) = post_json(
        &st,
        "/api/generate",
        r#"{"generator":"walk","seconds":2,"values":{"height_m":1.5,"speed_km_per_h":7.5},"changed":"speed_km_per_h"}"#,
    );
    let notes = v["notes"].to_string();
    assert!(notes.contains("walk-run transition"), "{notes}");
}

#[test]
fn exports_are_the_librarys_files() {
    let st = start();
    let body = r#"{"generator":"run","seconds":2,"values":{"speed_km_per_h":14},"changed":"speed_km_per_h"}"#;
    let host = format!("127.0.0.1:{}", st.port);
    let (status, headers, bvh) = http(st.port, "POST", "/api/export/bvh", &host, body.as_bytes());
    assert_eq!(status, 200);
    assert!(
        headers.contains("filename=\"gaitfit-run.bvh\""),
        "{headers}"
    );
    assert!(bvh.starts_with(b"HIERARCHY"));
    let (_, _, steps) = http(st.port, "POST", "/api/export/steps", &host, body.as_bytes());
    let steps = String::from_utf8_lossy(&steps);
    assert!(steps.starts_with("subject,gait,side"), "{steps}");
    // A 14 km/h run: after the start's acceleration (RUNNER's first steps from the stand), every
    // step is commanded at 14 km/h.
    let speeds: Vec<f64> = steps
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(6)?.parse().ok())
        .collect();
    let at_14 = speeds
        .iter()
        .filter(|v| (*v * 3.6 - 14.0).abs() < 1e-6)
        .count();
    assert!(at_14 >= speeds.len() / 2, "{speeds:?} m/s");
    assert!(speeds.iter().all(|v| *v * 3.6 <= 14.0 + 1e-6), "{speeds:?}");
    assert!(
        (speeds[speeds.len() - 1] * 3.6 - 14.0).abs() < 1e-6,
        "{speeds:?}"
    );
    let (_, v) = post_json(&st, "/api/export/gif", body);
    assert!(v["error"].as_str().unwrap_or("").contains("use one of"));
}
