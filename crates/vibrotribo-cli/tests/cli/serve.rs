//! `vibrotribo serve`: the API's numbers are the command line's (the run view against
//! `simulate`'s summary.json, the orbit diagram against `sweep`'s files, the power map
//! against `map`'s, the exported TOML run by `simulate`), bit for bit; a malformed request
//! gets 400 with the reason; SIGTERM stops the server cleanly; a burst of abandoned parameter
//! changes leaves the latest answered and the memory flat.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};

use serde_json::{Value, json};

use crate::util::*;

/// A server on a free port, stopped when dropped.
struct Server {
    child: Child,
    addr: String,
}

impl Server {
    fn start(args: &[&str]) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
            .arg("serve")
            .args(["--port", "0"])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("cannot start vibrotribo serve");
        let mut line = String::new();
        BufReader::new(child.stdout.as_mut().unwrap())
            .read_line(&mut line)
            .unwrap();
        let addr = line
            .split("http://")
            .nth(1)
            .and_then(|rest| rest.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_string();
        Server { child, addr }
    }

    /// `(status, body)` of `method path` with the JSON `body` (HTTP/1.0: the answer ends
    /// with the connection).
    fn request(&self, method: &str, path: &str, body: &str) -> (u16, String) {
        let mut stream = TcpStream::connect(&self.addr).unwrap();
        write!(
            stream,
            "{method} {path} HTTP/1.0\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            self.addr,
            body.len()
        )
        .unwrap();
        let mut answer = String::new();
        stream.read_to_string(&mut answer).unwrap();
        let (head, body) = answer.split_once("\r\n\r\n").unwrap();
        let status = head.split(' ').nth(1).unwrap().parse().unwrap();
        (status, body.to_string())
    }

    fn post(&self, path: &str, body: &Value) -> Value {
        let (status, text) = self.request("POST", path, &body.to_string());
        assert_eq!(status, 200, "POST {path} {body}: {text}");
        serde_json::from_str(&text).unwrap()
    }

    /// The JSON lines of a streamed answer.
    fn lines(&self, path: &str, body: &Value) -> Vec<Value> {
        let (status, text) = self.request("POST", path, &body.to_string());
        assert_eq!(status, 200, "POST {path} {body}: {text}");
        text.lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn float(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// `simulate`'s summary.json for `args`.
fn simulate_summary(args: &[&str]) -> Value {
    let dir = tempdir();
    let out = dir.path().to_str().unwrap();
    let mut all = vec!["simulate", "-q", "--out", out];
    all.extend_from_slice(args);
    let o = vibrotribo(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    manifest(dir.path(), "summary.json")
}

/// A column of a CSV file as numbers (empty cells: NaN).
fn column(path: &Path, name: &str) -> Vec<f64> {
    let (header, rows) = read_csv(path);
    let k = header.iter().position(|h| h == name).unwrap();
    rows.iter().map(|r| r[k].parse().unwrap_or(f64::NAN)).collect()
}

#[test]
fn run_view_is_simulate_bit_for_bit() {
    let server = Server::start(&[]);
    for (set, args) in [
        (json!({}), vec![]),
        (
            json!({"excitation.omega_ratio": "0.8", "harvester.load_resistance": 2e6}),
            vec![
                "--set",
                "excitation.omega_ratio=0.8",
                "--set",
                "harvester.load_resistance=2000000.0",
            ],
        ),
    ] {
        let view = server.post("/api/run", &json!({ "set": set }));
        let cli = simulate_summary(&args);
        let (api_power, cli_power) = (float(&view["average_power_w"]), float(&cli["average_power_w"]));
        assert_eq!(
            api_power.to_bits(),
            cli_power.to_bits(),
            "{set}: API {api_power:e} W, CLI {cli_power:e} W"
        );
        for key in ["impacts", "events_total", "sticks", "periods"] {
            assert_eq!(view["summary"][key], cli[key], "{set}: {key}");
        }
        assert_eq!(
            view["summary"]["motion"]["motion"], cli["motion"]["motion"],
            "{set}"
        );
        // The samples are the run's: the last one is at the run's end.
        let t = view["samples"]["t"].as_array().unwrap();
        let end = float(&cli["periods"]) * float(&cli["excitation_period_s"]);
        assert!(
            (float(t.last().unwrap()) - end).abs() <= 1e-9 * end,
            "{set}: last sample at {} s, run ends at {end} s",
            t.last().unwrap()
        );
    }
}

#[test]
fn exported_toml_runs_to_the_same_power() {
    let dir = tempdir();
    let config = config_file("impact_oscillator.toml");
    let server = Server::start(&[config.to_str().unwrap()]);
    let set = json!({"excitation.omega_ratio": "0.9"});
    let view = server.post("/api/run", &json!({ "set": set }));
    let (status, text) = server.request("POST", "/api/toml", &json!({ "set": set }).to_string());
    assert_eq!(status, 200, "{text}");
    let file = dir.path().join("exported.toml");
    std::fs::write(&file, text).unwrap();
    let cli = simulate_summary(&[file.to_str().unwrap()]);
    let direct = simulate_summary(&[config.to_str().unwrap(), "--set", "excitation.omega_ratio=0.9"]);
    assert_eq!(view["summary"]["impacts"], cli["impacts"]);
    assert_eq!(cli["impacts"], direct["impacts"]);
    match (view["average_power_w"].as_f64(), cli["average_power_w"].as_f64()) {
        (Some(a), Some(b)) => assert_eq!(a.to_bits(), b.to_bits(), "API {a:e} W, CLI {b:e} W"),
        (a, b) => assert_eq!(a, b, "power: API {a:?}, CLI {b:?}"),
    }
}

#[test]
fn orbit_diagram_and_map_are_sweep_and_map_bit_for_bit() {
    let server = Server::start(&[]);
    let dir = tempdir();
    let sweep_dir = dir.path().join("sweep");
    let o = vibrotribo(&[
        "sweep",
        "-q",
        "--param",
        "excitation.omega_ratio",
        "--from",
        "0.6",
        "--to",
        "0.9",
        "--steps",
        "4",
        "--transient",
        "30",
        "--recorded",
        "12",
        "--out",
        sweep_dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = server.lines(
        "/api/orbit",
        &json!({"x": {"param": "excitation.omega_ratio", "from": 0.6, "to": 0.9, "steps": 4},
                "transient": 30, "recorded": 12}),
    );
    assert_eq!(lines[0]["kind"], "start");
    assert_eq!(lines.last().unwrap()["kind"], "end");
    assert_eq!(lines.last().unwrap()["complete"], true);
    let params = column(&sweep_dir.join("summary.csv"), "param");
    let powers = column(&sweep_dir.join("summary.csv"), "average_power_w");
    let orbit_param = column(&sweep_dir.join("orbit.csv"), "param");
    let orbit_x1 = column(&sweep_dir.join("orbit.csv"), "x1_m");
    let points: Vec<&Value> = lines.iter().filter(|l| l["kind"] == "point").collect();
    assert_eq!(points.len(), params.len());
    for p in points {
        let x = float(&p["x"]);
        let k = params.iter().position(|&v| v.to_bits() == x.to_bits()).unwrap();
        let api = float(&p["average_power_w"]);
        assert_eq!(
            api.to_bits(),
            powers[k].to_bits(),
            "Ω = {x}: API {api:e} W, sweep {:e} W",
            powers[k]
        );
        let cli_x1: Vec<f64> = orbit_param
            .iter()
            .zip(&orbit_x1)
            .filter(|(v, _)| v.to_bits() == x.to_bits())
            .map(|(_, &x1)| x1)
            .collect();
        let strobe = p["strobe"].as_array().unwrap();
        let api_x1: Vec<f64> = strobe.iter().step_by(3).map(float).collect();
        assert_eq!(api_x1.len(), 12, "Ω = {x}");
        assert_eq!(
            api_x1.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            cli_x1.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "Ω = {x}: x1 at t = nT"
        );
    }
    // The power map against `vibrotribo map`.
    let map_dir = dir.path().join("map");
    let o = vibrotribo(&[
        "map",
        "-q",
        "--x",
        "excitation.omega_ratio",
        "--x-from",
        "0.7",
        "--x-to",
        "0.8",
        "--x-steps",
        "2",
        "--y",
        "oscillator.restitution",
        "--y-from",
        "0.5",
        "--y-to",
        "0.7",
        "--y-steps",
        "2",
        "--transient",
        "20",
        "--recorded",
        "10",
        "--out",
        map_dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = server.lines(
        "/api/map",
        &json!({"x": {"param": "excitation.omega_ratio", "from": 0.7, "to": 0.8, "steps": 2},
                "y": {"param": "oscillator.restitution", "from": 0.5, "to": 0.7, "steps": 2},
                "transient": 20, "recorded": 10}),
    );
    let (header, rows) = read_csv(&map_dir.join("map.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (cx, cy, cp) = (col("x"), col("y"), col("average_power_w"));
    let points: Vec<&Value> = lines.iter().filter(|l| l["kind"] == "point").collect();
    assert_eq!(points.len(), 4);
    assert_eq!(rows.len(), 4);
    for p in points {
        let (x, y) = (float(&p["x"]), float(&p["y"]));
        let row = rows
            .iter()
            .find(|r| r[cx].parse::<f64>().unwrap() == x && r[cy].parse::<f64>().unwrap() == y)
            .unwrap_or_else(|| panic!("no map.csv row at ({x}, {y})"));
        let cli: f64 = row[cp].parse().unwrap();
        let api = float(&p["average_power_w"]);
        assert_eq!(
            api.to_bits(),
            cli.to_bits(),
            "({x}, {y}): API {api:e} W, map {cli:e} W"
        );
    }
}

#[test]
fn malformed_requests_get_400_with_the_reason() {
    let server = Server::start(&[]);
    let orbit = |x: Value| json!({"x": x}).to_string();
    let cases: Vec<(&str, String, &str)> = vec![
        ("/api/run", "{not json".into(), "malformed request"),
        ("/api/run", r#"{"sett": {}}"#.into(), "unknown field"),
        (
            "/api/run",
            r#"{"set": {"oscillator.mass": "1"}}"#.into(),
            "oscillator.mass",
        ),
        (
            "/api/run",
            r#"{"set": {"oscillator.restitution": "1.5"}}"#.into(),
            "restitution",
        ),
        (
            "/api/check",
            r#"{"set": {"excitation.omega_ratio": "-1"}}"#.into(),
            "omega_ratio",
        ),
        ("/api/toml", r#"{"set": {"run.periods": "0"}}"#.into(), "periods"),
        (
            "/api/orbit",
            orbit(json!({"param": "excitation.omega_ratio", "from": 0.5, "to": 1.0, "steps": 0})),
            "steps",
        ),
        (
            "/api/orbit",
            orbit(json!({"param": "excitation.omega_ratio", "from": 0.5, "to": 1.0, "steps": 100000000_u64})),
            "limit",
        ),
        (
            "/api/orbit",
            orbit(json!({"param": "no.such_key", "from": 0.5, "to": 1.0, "steps": 3})),
            "no.such_key",
        ),
        (
            "/api/map",
            orbit(json!({"param": "excitation.omega_ratio", "from": 0.5, "to": 1.0, "steps": 3})),
            "x and y",
        ),
        (
            "/api/orbit",
            r#"{"x": {"param": "excitation.omega_ratio"}}"#.into(),
            "missing field",
        ),
    ];
    for (path, body, says) in cases {
        let (status, text) = server.request("POST", path, &body);
        assert_eq!(status, 400, "POST {path} {body}: {text}");
        let error: Value = serde_json::from_str(&text).unwrap_or_else(|_| panic!("not JSON: {text}"));
        let message = error["error"].as_str().unwrap();
        assert!(
            message.contains(says),
            "POST {path} {body}: {message:?} lacks {says:?}"
        );
    }
    let (status, text) = server.request("GET", "/api/nothing", "");
    assert_eq!(status, 404, "{text}");
    // The server is still there.
    let schema = server.request("GET", "/api/schema", "");
    assert_eq!(schema.0, 200);
}

#[test]
fn page_schema_and_assets_are_served() {
    let server = Server::start(&[]);
    let (status, page) = server.request("GET", "/", "");
    assert_eq!(status, 200);
    for id in [
        "power-value",
        "run-view",
        "orbit-diagram",
        "basins-view",
        "map-view",
        "export-toml",
        "status",
    ] {
        assert!(
            page.contains(&format!("data-testid=\"{id}\"")),
            "the page lacks {id}"
        );
    }
    for asset in [
        "app.js",
        "app.css",
        "uPlot.iife.min.js",
        "uPlot.min.css",
        "uPlot.LICENSE",
    ] {
        let (status, _) = server.request("GET", &format!("/assets/{asset}"), "");
        assert_eq!(status, 200, "{asset}");
    }
    let (status, text) = server.request("GET", "/api/schema", "");
    assert_eq!(status, 200);
    let schema: Value = serde_json::from_str(&text).unwrap();
    // Every key of the configuration reference, with the reference's unit.
    let reference = vibrotribo(&["config-reference"]);
    let reference = String::from_utf8_lossy(&reference.stdout);
    let keys = schema["keys"].as_array().unwrap();
    assert!(keys.len() > 40, "{} keys", keys.len());
    for k in keys {
        let key = k["key"].as_str().unwrap();
        let name = key.split_once('.').map_or(key, |(_, n)| n);
        assert!(
            reference.contains(&format!("| `{name}` | {} |", k["unit"].as_str().unwrap())),
            "{key}"
        );
    }
    let omega = keys
        .iter()
        .find(|k| k["key"] == "excitation.omega_ratio")
        .unwrap();
    let default = vibrotribo::config::Config::default().chain().omega_ratio();
    let shown: f64 = omega["value"].as_str().unwrap().parse().unwrap();
    assert!((shown - default).abs() <= 1e-9 * default, "{shown} vs {default}");
}

#[test]
fn sigterm_stops_the_server_cleanly() {
    let mut server = Server::start(&[]);
    assert_eq!(server.request("GET", "/api/schema", "").0, 200);
    let status = Command::new("kill")
        .args(["-TERM", &server.child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let exit = server.child.wait().unwrap();
    assert!(exit.success(), "exit status after SIGTERM: {exit:?}");
    let mut rest = String::new();
    server
        .child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut rest)
        .unwrap();
    assert!(rest.contains("stopped"), "{rest:?}");
}

/// The answer of `path` read as a stream: the status and a reader at the start of the body.
fn open_stream(server: &Server, path: &str, body: &Value) -> (u16, BufReader<TcpStream>) {
    let mut stream = TcpStream::connect(&server.addr).unwrap();
    let body = body.to_string();
    write!(
        stream,
        "POST {path} HTTP/1.0\r\nHost: {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        server.addr,
        body.len()
    )
    .unwrap();
    let mut reader = BufReader::new(stream);
    let mut status = String::new();
    reader.read_line(&mut status).unwrap();
    loop {
        let mut header = String::new();
        reader.read_line(&mut header).unwrap();
        if header.trim().is_empty() {
            break;
        }
    }
    (status.split(' ').nth(1).unwrap().parse().unwrap(), reader)
}

fn next_line(reader: &mut BufReader<TcpStream>) -> Value {
    let mut line = String::new();
    reader.read_line(&mut line).unwrap();
    serde_json::from_str(&line).unwrap_or_else(|_| panic!("not a JSON line: {line:?}"))
}

#[test]
fn a_request_sent_earlier_but_arriving_later_never_supersedes_the_newest() {
    let server = Server::start(&[]);
    let orbit = |seq: u64| {
        json!({"x": {"param": "excitation.omega_ratio", "from": 0.5, "to": 1.1, "steps": 60},
               "transient": 400, "recorded": 20, "mechanics_only": true, "seq": seq})
    };
    // The newest request (seq 20) is under way: its first point has arrived.
    let (status, mut newest) = open_stream(&server, "/api/orbit", &orbit(20));
    assert_eq!(status, 200);
    assert_eq!(next_line(&mut newest)["kind"], "start");
    assert_eq!(next_line(&mut newest)["kind"], "point");
    // An older request (seq 10) reaches the server now: refused, for both lanes' kinds.
    let (status, text) = server.request("POST", "/api/orbit", &orbit(10).to_string());
    assert_eq!(status, 409, "{text}");
    assert!(text.contains("outdated"), "{text}");
    // The newest runs to its end, every value delivered.
    let mut points = 1;
    let end = loop {
        let line = next_line(&mut newest);
        match line["kind"].as_str() {
            Some("point") => points += 1,
            Some("end") => break line,
            other => panic!("unexpected line {other:?}"),
        }
    };
    assert_eq!(end["complete"], true, "the newest was stopped: {end}");
    assert_eq!(points, 60);
    // A request sent later (seq 30) does supersede a running one (seq 25).
    let (_, mut older) = open_stream(&server, "/api/orbit", &orbit(25));
    assert_eq!(next_line(&mut older)["kind"], "start");
    let (_, mut newer) = open_stream(&server, "/api/orbit", &orbit(30));
    assert_eq!(next_line(&mut newer)["kind"], "start");
    let end = loop {
        let line = next_line(&mut older);
        if line["kind"] == "end" {
            break line;
        }
    };
    assert_eq!(end["complete"], false, "{end}");
    // The run view's lane orders by seq too.
    let view = server.post("/api/run", &json!({"seq": 5}));
    assert!(view["average_power_w"].is_number());
    let (status, text) = server.request("POST", "/api/run", &json!({"seq": 4}).to_string());
    assert_eq!(status, 409, "{text}");
}

/// Sends `count` run-view parameter changes (Ω from `0.6 + 0.0002·first`), each abandoned by
/// its client as soon as it is sent, as the page's AbortController does; then asks for Ω =
/// 0.7999 until answered (an abandoned request handled later supersedes it: 409, asked again,
/// as the page does) and returns that view.
fn abandon_then_ask(server: &Server, first: usize, count: usize) -> Value {
    for k in first..first + count {
        let body =
            json!({"set": {"excitation.omega_ratio": format!("{}", 0.6 + 0.0002 * (k % 2000) as f64)}})
                .to_string();
        let mut stream = TcpStream::connect(&server.addr).unwrap();
        write!(
            stream,
            "POST /api/run HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .unwrap();
    }
    let latest = json!({"set": {"excitation.omega_ratio": "0.7999"}}).to_string();
    for _ in 0..100 {
        let (status, text) = server.request("POST", "/api/run", &latest);
        if status != 409 {
            assert_eq!(status, 200, "{text}");
            return serde_json::from_str(&text).unwrap();
        }
    }
    panic!("the latest parameter change was superseded 100 times");
}

/// The server's resident heap in KiB (`RssAnon`: its anonymous pages, not the program's own
/// pages mapped from its file), once it has been idle for a second.
#[cfg(target_os = "linux")]
fn idle_heap_kib(server: &Server) -> u64 {
    std::thread::sleep(std::time::Duration::from_secs(1));
    let status = std::fs::read_to_string(format!("/proc/{}/status", server.child.id())).unwrap();
    let line = status.lines().find(|l| l.starts_with("RssAnon:")).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

#[test]
fn after_a_burst_of_abandoned_changes_the_latest_is_answered_with_the_clis_numbers() {
    let server = Server::start(&[]);
    let view = abandon_then_ask(&server, 0, 200);
    let cli = simulate_summary(&["--set", "excitation.omega_ratio=0.7999"]);
    let (api_power, cli_power) = (float(&view["average_power_w"]), float(&cli["average_power_w"]));
    assert_eq!(
        api_power.to_bits(),
        cli_power.to_bits(),
        "API {api_power:e} W, CLI {cli_power:e} W"
    );
}

/// With glibc's default arenas (up to eight per core, one per blocking thread that computes)
/// the heap grows by 13 to 15 MiB over 8000 abandoned run requests, and still climbs after
/// them; bounded to two arenas and trimmed, by about 3 MiB.
#[test]
#[cfg(target_os = "linux")]
#[ignore = "8000 requests: about 10 s"]
fn memory_stays_flat_under_abandoned_parameter_changes() {
    let server = Server::start(&[]);
    let start = idle_heap_kib(&server);
    abandon_then_ask(&server, 0, 2000);
    let early = idle_heap_kib(&server);
    abandon_then_ask(&server, 2000, 6000);
    let after = idle_heap_kib(&server);
    assert!(
        after <= start + 8 * 1024,
        "heap {start} KiB at start, {early} KiB after 2000 abandoned requests, {after} KiB after 8000"
    );
}

/// `continue`'s branch.csv (header and rows, as text) for `args`.
fn continue_branch_csv(args: &[&str]) -> (Vec<String>, Vec<Vec<String>>) {
    let dir = tempdir();
    let mut all = vec!["continue", "--out", dir.path().to_str().unwrap()];
    all.extend_from_slice(args);
    let o = vibrotribo(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    read_csv(&dir.path().join("branch.csv"))
}

#[test]
fn branches_are_continue_branch_csv_bit_for_bit() {
    let server = Server::start(&[]);
    let (header, rows) = continue_branch_csv(&[
        "--param",
        "mass_ratio",
        "--from",
        "2.6",
        "--to",
        "3.0",
        "--mechanics-only",
    ]);
    let view = server.post(
        "/api/branches",
        &json!({"param": "mass_ratio", "from": 2.6, "to": 3.0, "mechanics_only": true}),
    );
    let strings = |v: &Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(strings(&view["columns"]), header);
    let api_rows: Vec<Vec<String>> = view["rows"].as_array().unwrap().iter().map(strings).collect();
    assert!(!rows.is_empty());
    assert_eq!(api_rows, rows, "the API's branch is not continue's branch.csv");
    // The drawn points are the rows' points, in order, with their stability.
    let drawn: Vec<(String, String)> = view["branches"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|b| b["points"].as_array().unwrap().iter())
        .map(|p| (float(&p["param"]).to_string(), p["stable"].to_string()))
        .collect();
    let listed: Vec<(String, String)> = rows.iter().map(|r| (r[2].clone(), r[3].clone())).collect();
    assert_eq!(drawn, listed);
    // The section of a period-P orbit at t = 0 is the branch's state: x_i of branch.csv.
    let first = &view["branches"][0]["points"][0]["sections"];
    let x1: f64 = rows[0][header.iter().position(|h| h == "x1_m").unwrap()]
        .parse()
        .unwrap();
    assert_eq!(float(&first[0][0]).to_bits(), x1.to_bits());
    // The Neimark–Sacker point `continue` lists is marked.
    assert!(
        view["bifurcations"]
            .as_array()
            .unwrap()
            .iter()
            .any(|b| b["kind"] == "neimark_sacker"),
        "{}",
        view["bifurcations"]
    );
}

#[test]
fn basins_are_the_basins_commands_classification_bit_for_bit() {
    let server = Server::start(&[]);
    let dir = tempdir();
    let set = ["oscillator.masses=[0.09,0.12,0.09]", "gap_ratio=1.09"];
    let o = vibrotribo(&[
        "basins",
        "-q",
        "--set",
        set[0],
        "--set",
        set[1],
        "--x",
        "run.initial_positions[1]",
        "--x-from",
        "-0.02",
        "--x-to",
        "0.018",
        "--y",
        "run.initial_velocities[1]",
        "--y-from",
        "-3",
        "--y-to",
        "3",
        "--grid",
        "5x6",
        "--transient",
        "300",
        "--recorded",
        "32",
        "--mechanics-only",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = server.lines(
        "/api/basins",
        &json!({"set": {"oscillator.masses": "[0.09,0.12,0.09]", "gap_ratio": "1.09"},
                "x": {"param": "run.initial_positions[1]", "from": -0.02, "to": 0.018, "steps": 5},
                "y": {"param": "run.initial_velocities[1]", "from": -3, "to": 3, "steps": 6},
                "transient": 300, "recorded": 32, "mechanics_only": true}),
    );
    let start = &lines[0];
    let classes = lines
        .iter()
        .find(|l| l["kind"] == "classes")
        .unwrap_or_else(|| panic!("no classification in {:?}", lines.last()));
    let (_, basins) = read_csv(&dir.path().join("basins.csv"));
    let (at_header, attractors) = read_csv(&dir.path().join("attractors.csv"));
    assert_eq!(basins.len(), 30);
    let xs = start["xs"].as_array().unwrap();
    let ys = start["ys"].as_array().unwrap();
    let labels = classes["labels"].as_array().unwrap();
    for (k, row) in basins.iter().enumerate() {
        let (x, y) = (float(&xs[k % 5]), float(&ys[k / 5]));
        assert_eq!(
            (x.to_string(), y.to_string()),
            (row[0].clone(), row[1].clone()),
            "start {k}"
        );
        let label = labels[k].as_u64().map_or(String::new(), |a| a.to_string());
        assert_eq!(label, row[2], "start {k} at ({x}, {y})");
    }
    let api = classes["attractors"].as_array().unwrap();
    assert_eq!(api.len(), attractors.len());
    assert!(api.len() >= 2, "Fig. 7's two coexisting orbits: {api:?}");
    let cell = |row: &[String], name: &str| row[at_header.iter().position(|h| h == name).unwrap()].clone();
    let text = |v: &Value| match v {
        Value::Null => String::new(),
        Value::Number(n) if n.is_u64() => n.to_string(),
        v => float(v).to_string(),
    };
    for (a, row) in api.iter().zip(&attractors) {
        for name in [
            "attractor",
            "period",
            "starts",
            "fraction",
            "fraction_se",
            "impacts_per_period",
            "average_power_w",
            "power_se_w",
        ] {
            assert_eq!(
                text(&a[name]),
                cell(row, name),
                "attractor {}: {name}",
                a["attractor"]
            );
        }
        let state: Vec<String> = a["state"].as_array().unwrap().iter().map(text).collect();
        assert_eq!(
            state,
            row[8..].to_vec(),
            "attractor {}: section state",
            a["attractor"]
        );
    }
}
