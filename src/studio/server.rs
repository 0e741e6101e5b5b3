//! The studio's HTTP server: axum on a single-threaded tokio runtime, bound to 127.0.0.1 only.
//!
//! Generation is CPU work and runs on tokio's blocking pool, one request at a time per
//! connection; a panic there (a bug) becomes a 500 answer with the message, never a dead
//! server. Every request passes the guard ([`refusal`]) first: the peer must be a loopback address, the
//! `Host` header must name a loopback host (a page elsewhere cannot reach the studio by
//! rebinding a DNS name to 127.0.0.1), and an `Origin`, when sent, must be loopback too.
//!
//! The page (`assets/studio/`) is compiled into the binary with `include_str!`; it loads
//! nothing from anywhere else (its Content-Security-Policy says so to the browser).
use super::export::{export, formats};
use super::figure::figure_json;
use super::plots::{data_points, plots, DataPoints};
use super::session::{generate, parse_request, Generated, Sources};
use super::StudioError;
use axum::body::Bytes;
use axum::extract::{ConnectInfo, Path as UrlPath, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use serde::Serialize;
use serde_json::json;
use std::collections::BTreeMap;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

const INDEX_HTML: &str = include_str!("../../assets/studio/index.html");
const STUDIO_JS: &str = include_str!("../../assets/studio/studio.js");
const STUDIO_CSS: &str = include_str!("../../assets/studio/studio.css");

/// The page may load only what this server serves (and download the blobs it makes).
const CSP: &str = "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; \
                   connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

/// Port used when none is given.
pub const DEFAULT_PORT: u16 = 8765;

/// How the studio is started.
#[derive(Debug, Clone)]
pub struct StudioConfig {
    /// TCP port on 127.0.0.1 (0: any free port).
    pub port: u16,
    /// Folder of refitted relations (`gaitfit fit` writes `fits/`).
    pub fits: PathBuf,
    /// Folder of trials tables whose points the plots show (`data/`).
    pub data: PathBuf,
}

struct AppState {
    sources: Sources,
    data: BTreeMap<String, DataPoints>,
    data_notes: Vec<String>,
    config: StudioConfig,
}

/// Binds 127.0.0.1:`port`, calls `ready` with the bound address (to print it, open a browser),
/// then serves until the process ends.
pub fn run(config: StudioConfig, ready: impl FnOnce(SocketAddr)) -> Result<(), StudioError> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .build()
        .map_err(|e| StudioError::Server(format!("cannot start the runtime: {e}")))?;
    let (data, data_notes) = data_points(&config.data);
    let state = Arc::new(AppState {
        sources: Sources {
            fits: config.fits.clone(),
        },
        data,
        data_notes,
        config: config.clone(),
    });
    rt.block_on(async move {
        let addr = SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), config.port);
        let listener = tokio::net::TcpListener::bind(addr).await.map_err(|e| {
            StudioError::Server(format!(
                "cannot listen on {addr}: {e}; give another --port (0 picks a free one)"
            ))
        })?;
        let bound = listener
            .local_addr()
            .map_err(|e| StudioError::Server(format!("no local address: {e}")))?;
        ready(bound);
        axum::serve(
            listener,
            router(state).into_make_service_with_connect_info::<SocketAddr>(),
        )
        .await
        .map_err(|e| StudioError::Server(e.to_string()))
    })
}

fn router(state: Arc<AppState>) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/studio.js", get(script))
        .route("/studio.css", get(style))
        .route("/api/catalog", get(catalog))
        .route("/api/data", get(data))
        .route("/api/generate", post(generate_handler))
        .route("/api/export/{format}", post(export_handler))
        .fallback(not_found)
        .layer(middleware::from_fn(guard))
        .with_state(state)
}

/// Whether `host` (a `Host` header value: `name[:port]`, `[v6]:port`) names this machine's
/// loopback interface.
pub fn host_is_loopback(host: &str) -> bool {
    let name = if let Some(rest) = host.strip_prefix('[') {
        rest.split(']').next().unwrap_or("")
    } else {
        host.rsplit_once(':').map_or(host, |(h, _)| h)
    };
    name.eq_ignore_ascii_case("localhost")
        || name.parse::<IpAddr>().is_ok_and(|ip| ip.is_loopback())
}

/// Why a request must be refused, if it must: a peer that is not loopback, a `Host` that does
/// not name loopback, or an `Origin` (when sent) that is not loopback.
pub fn refusal(peer: IpAddr, host: Option<&str>, origin: Option<&str>) -> Option<String> {
    if !peer.is_loopback() {
        return Some(format!("peer {peer} is not loopback"));
    }
    let host = host.unwrap_or("");
    if !host_is_loopback(host) {
        return Some(format!("Host {host:?} is not a loopback name"));
    }
    if let Some(o) = origin {
        let h = o
            .strip_prefix("http://")
            .or_else(|| o.strip_prefix("https://"))
            .unwrap_or("");
        if !host_is_loopback(h) {
            return Some(format!("Origin {o:?} is not this studio"));
        }
    }
    None
}

/// Refuses every request that does not come from, and name, this machine's loopback.
async fn guard(
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    request: Request,
    next: Next,
) -> Response {
    let headers = request.headers();
    let text = |h: header::HeaderName| headers.get(h).map(|v| v.to_str().unwrap_or("\u{fffd}"));
    match refusal(peer.ip(), text(header::HOST), text(header::ORIGIN)) {
        Some(why) => (
            StatusCode::FORBIDDEN,
            format!("gaitfit studio serves this machine only (127.0.0.1): {why}\n"),
        )
            .into_response(),
        None => next.run(request).await,
    }
}

fn asset(content_type: &'static str, body: &'static str) -> Response {
    let mut h = HeaderMap::new();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    h.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(CSP),
    );
    h.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    (h, body).into_response()
}

async fn index() -> Response {
    asset("text/html; charset=utf-8", INDEX_HTML)
}

async fn script() -> Response {
    asset("text/javascript; charset=utf-8", STUDIO_JS)
}

async fn style() -> Response {
    asset("text/css; charset=utf-8", STUDIO_CSS)
}

async fn not_found() -> Response {
    (StatusCode::NOT_FOUND, "not found\n").into_response()
}

async fn catalog(State(s): State<Arc<AppState>>) -> Response {
    axum::Json(json!({
        "version": crate::GAITFIT_VERSION,
        "generators": [
            {"name": "run", "label": "run — RUNNER (Bruderlin & Calvert 1996)", "fps": 120.0,
             "from_rest": "always (a run starts from a stand)", "stop": true,
             "command": "gaitfit generate run"},
            {"name": "walk", "label": "walk — KLAW (Bruderlin & Calvert 1989)", "fps": 100.0,
             "from_rest": "optional", "stop": true, "command": "gaitfit generate walk"},
            {"name": "generalize", "label": "generalize — Ko & Badler (1993)", "fps": 120.0,
             "from_rest": "no", "stop": false, "command": "gaitfit generate generalize"},
        ],
        "exports": formats(),
        "fits": s.config.fits.display().to_string(),
        "data": s.config.data.display().to_string(),
        "data_notes": s.data_notes,
    }))
    .into_response()
}

async fn data(State(s): State<Arc<AppState>>) -> Response {
    axum::Json(json!({ "relations": s.data, "notes": s.data_notes })).into_response()
}

/// A step as the page's table shows it (the papers' units).
#[derive(Serialize)]
struct StepView {
    side: &'static str,
    time_s: Option<f64>,
    speed_km_per_h: Option<f64>,
    step_length_m: Option<f64>,
    step_freq_steps_per_min: Option<f64>,
    stance_time_s: Option<f64>,
    flight_time_s: Option<f64>,
    double_support_pct_cycle: Option<f64>,
}

/// A refused input is an ordinary answer (`200`, `"ok": false` and the message the command line
/// prints), so that the browser does not log it as a failed resource; only the server's own
/// failures are HTTP errors.
fn error_response(e: &StudioError) -> Response {
    let status = match e {
        StudioError::Request(_) | StudioError::Generate(_) | StudioError::Library(_) => {
            StatusCode::OK
        }
        _ => StatusCode::INTERNAL_SERVER_ERROR,
    };
    (
        status,
        axum::Json(json!({"ok": false, "error": e.to_string()})),
    )
        .into_response()
}

fn panic_response(e: tokio::task::JoinError) -> Response {
    let why = match e.try_into_panic() {
        Ok(p) => p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "a panic".into()),
        Err(e) => e.to_string(),
    };
    (
        StatusCode::INTERNAL_SERVER_ERROR,
        axum::Json(json!({
            "ok": false,
            "error": format!("internal error (a gaitfit bug, please report it with these settings): {why}")
        })),
    )
        .into_response()
}

/// The answer to `/api/generate` (serialized straight from these types: the frames are most
/// of it).
#[derive(Serialize)]
struct GenerateAnswer<'a> {
    ok: bool,
    generator: super::session::GeneratorKind,
    controls: &'a [super::controls::Control],
    locks: &'a [String],
    flight_from_height: bool,
    relations: super::session::RelationsChoice,
    relations_source: &'a str,
    notes: &'a [String],
    figure: super::figure::FigureJson,
    steps: Vec<StepView>,
    plots: Vec<super::plots::Plot>,
    timing: Timing,
}

/// Server-side times of one answer, ms (shown on the page).
#[derive(Serialize)]
struct Timing {
    /// Resolving the parameters and generating the motion.
    generate_ms: f64,
    /// Everything before encoding the answer (generation, figure, plots).
    server_ms: f64,
}

fn generate_json(body: &[u8], s: &AppState) -> Result<Vec<u8>, StudioError> {
    let t0 = Instant::now();
    let req = parse_request(body)?;
    let g: Generated = generate(&req, &s.sources)?;
    let generate_ms = t0.elapsed().as_secs_f64() * 1e3;
    let steps: Vec<StepView> = g
        .steps
        .iter()
        .map(|r| StepView {
            side: match r.side {
                Some(crate::events::Side::Left) => "left",
                Some(crate::events::Side::Right) => "right",
                None => "",
            },
            time_s: r.time_s,
            speed_km_per_h: r.speed_m_per_s.map(|v| v * 3.6),
            step_length_m: r.step_length_m,
            step_freq_steps_per_min: r.step_freq_hz.map(|f| f * 60.0),
            stance_time_s: r.stance_time_s,
            flight_time_s: r.flight_time_s,
            double_support_pct_cycle: r.double_support_pct_cycle,
        })
        .collect();
    let figure = figure_json(&g.motion);
    let plots = plots(&g, &s.sources.fits);
    let answer = GenerateAnswer {
        ok: true,
        generator: g.generator,
        controls: &g.controls,
        locks: &g.locks,
        flight_from_height: g.flight_from_height,
        relations: g.relations,
        relations_source: &g.relations_source,
        notes: &g.notes,
        figure,
        steps,
        plots,
        timing: Timing {
            generate_ms,
            server_ms: t0.elapsed().as_secs_f64() * 1e3,
        },
    };
    serde_json::to_vec(&answer)
        .map_err(|e| StudioError::Server(format!("encoding the answer: {e}")))
}

async fn generate_handler(State(s): State<Arc<AppState>>, body: Bytes) -> Response {
    let res = tokio::task::spawn_blocking(move || generate_json(&body, &s)).await;
    match res {
        Ok(Ok(bytes)) => ([(header::CONTENT_TYPE, "application/json")], bytes).into_response(),
        Ok(Err(e)) => error_response(&e),
        Err(e) => panic_response(e),
    }
}

async fn export_handler(
    State(s): State<Arc<AppState>>,
    UrlPath(format): UrlPath<String>,
    body: Bytes,
) -> Response {
    let res = tokio::task::spawn_blocking(move || {
        let req = parse_request(&body)?;
        let g = generate(&req, &s.sources)?;
        export(&g, &format)
    })
    .await;
    match res {
        Ok(Ok(d)) => {
            let disposition = format!("attachment; filename=\"{}\"", d.filename);
            let mut h = HeaderMap::new();
            h.insert(
                header::CONTENT_TYPE,
                HeaderValue::from_static(d.content_type),
            );
            if let Ok(v) = HeaderValue::from_str(&disposition) {
                h.insert(header::CONTENT_DISPOSITION, v);
            }
            (h, d.bytes).into_response()
        }
        Ok(Err(e)) => error_response(&e),
        Err(e) => panic_response(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_hosts() {
        for h in [
            "127.0.0.1:8765",
            "localhost:1",
            "LOCALHOST",
            "[::1]:80",
            "127.3.4.5",
        ] {
            assert!(host_is_loopback(h), "{h}");
        }
        for h in [
            "evil.example:8765",
            "192.168.1.2:8765",
            "",
            "[2001:db8::1]:80",
            "0.0.0.0",
        ] {
            assert!(!host_is_loopback(h), "{h}");
        }
    }

    #[test]
    fn only_loopback_peers_hosts_and_origins_pass() {
        let lo: IpAddr = "127.0.0.1".parse().unwrap();
        let h = Some("127.0.0.1:8765");
        assert_eq!(refusal(lo, h, None), None);
        assert_eq!(refusal(lo, h, Some("http://127.0.0.1:8765")), None);
        assert_eq!(
            refusal("::1".parse().unwrap(), Some("[::1]:8765"), None),
            None
        );
        let lan: IpAddr = "192.168.1.20".parse().unwrap();
        assert!(refusal(lan, h, None).unwrap().contains("not loopback"));
        assert!(refusal("10.0.0.1".parse().unwrap(), h, None).is_some());
        assert!(refusal(lo, Some("rebound.example:8765"), None).is_some());
        assert!(refusal(lo, None, None).is_some());
        assert!(refusal(lo, h, Some("http://evil.example")).is_some());
        assert!(refusal(lo, h, Some("null")).is_some());
    }
}
