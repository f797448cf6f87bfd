//! The HTTP routes: the page, the timeline's state and a frame's values
//! (with `iterations: Auto`'s count), renders, picks, edits, saves and
//! server-sent events. Every route is behind `guard::check`.

use super::renderer::Stage;
use super::view::{View, NOT_DIGITS};
use super::{Event, State};
use crate::exact::{Component, Coordinates};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::sse::{KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

type Shared = axum::extract::State<Arc<State>>;

pub fn router(state: Arc<State>) -> Router {
    Router::new()
        .route("/", get(super::page::index))
        .route("/explore.js", get(super::page::script))
        .route("/explore.css", get(super::page::style))
        .route("/api/state", get(timeline_state))
        .route("/api/values", get(values))
        .route("/api/digits", get(digits))
        .route("/api/iterations", get(iterations))
        .route("/api/render", post(render))
        .route("/api/pick", post(pick))
        .route("/api/estimate", post(estimate))
        .route("/api/edit", post(edit))
        .route("/api/save", post(save))
        .route("/api/reload", post(reload))
        .route("/api/events", get(events))
        .layer(axum::middleware::from_fn_with_state(
            state.clone(),
            super::guard::check,
        ))
        .layer(axum::middleware::map_response(never_cached))
        .with_state(state)
}

/// Every answer is of this session only: nothing is cached or framed.
async fn never_cached(mut response: Response) -> Response {
    let headers = response.headers_mut();
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    headers.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    response
}

/// A refusal with its reason as plain text.
fn refused(status: StatusCode, message: impl Into<String>) -> Response {
    (status, message.into()).into_response()
}

/// A key as the page shows it.
#[derive(Serialize)]
struct KeyShown {
    time: f64,
    value: Vec<f64>,
}

#[derive(Serialize)]
struct TrackShown {
    name: String,
    interpolation: String,
    keys: Vec<KeyShown>,
}

/// The timeline as the page shows it.
#[derive(Serialize)]
struct TimelineState {
    name: String,
    path: Option<String>,
    dirty: bool,
    fps: f64,
    frames: u32,
    width: u32,
    height: u32,
    samples: u32,
    tracks: Vec<TrackShown>,
    parameters: Vec<(&'static str, usize)>,
    /// The parameters whose value may be strings of digits (points).
    digit_points: Vec<&'static str>,
    plan: Vec<String>,
    command: String,
    text: String,
}

fn state_of(document: &super::Document) -> TimelineState {
    let t = &document.timeline;
    let tracks = t
        .tracks
        .iter()
        .map(|track| TrackShown {
            name: track.name.clone(),
            interpolation: format!("{:?}", track.interpolation),
            keys: track
                .key_times
                .iter()
                .map(|&time| KeyShown {
                    time,
                    value: track.sample(time),
                })
                .collect(),
        })
        .collect();
    let shown = document.path().map(|p| p.display().to_string());
    TimelineState {
        name: document.name(),
        command: format!(
            "mandelreel render {}",
            shown.clone().unwrap_or_else(|| document.name())
        ),
        path: shown,
        dirty: document.dirty(),
        fps: t.fps,
        frames: t.frame_count,
        width: t.width,
        height: t.height,
        samples: t.base.samples_per_pixel.max(1),
        tracks,
        parameters: crate::timeline::PARAMETERS.to_vec(),
        digit_points: crate::timeline::parameters::all()
            .filter(|p| p.digits.is_some())
            .map(|p| p.name)
            .collect(),
        plan: crate::job::describe::plan_lines(&t.base),
        text: document.text.clone(),
    }
}

async fn timeline_state(state: Shared) -> Response {
    let document = state.document.lock().expect("document");
    Json(state_of(&document)).into_response()
}

#[derive(Deserialize)]
struct FrameQuery {
    frame: u32,
}

async fn values(state: Shared, query: axum::extract::Query<FrameQuery>) -> Response {
    let timeline = state.document.lock().expect("document").timeline.clone();
    let view = View {
        frame: query.frame,
        ..View::default()
    };
    if let Err(message) = view.prepare(&timeline) {
        return refused(StatusCode::UNPROCESSABLE_ENTITY, message);
    }
    Json(super::view::values(&timeline, query.frame)).into_response()
}

async fn digits(state: Shared, query: axum::extract::Query<FrameQuery>) -> Response {
    let timeline = state.document.lock().expect("document").timeline.clone();
    if query.frame >= timeline.frame_count {
        let last = timeline.frame_count - 1;
        return refused(
            StatusCode::UNPROCESSABLE_ENTITY,
            format!("frame {} is past the last frame ({last})", query.frame),
        );
    }
    Json(super::view::digits(&timeline, query.frame)).into_response()
}

async fn iterations(state: Shared, query: axum::extract::Query<FrameQuery>) -> Response {
    let timeline = state.document.lock().expect("document").timeline.clone();
    if query.frame >= timeline.frame_count {
        let last = timeline.frame_count - 1;
        let message = format!("frame {} is past the last frame ({last})", query.frame);
        return refused(StatusCode::UNPROCESSABLE_ENTITY, message);
    }
    // A deep frame's first count follows a high-precision orbit.
    let shown =
        tokio::task::spawn_blocking(move || super::view::iterations(&timeline, query.frame));
    match shown.await {
        Ok(shown) => Json(shown).into_response(),
        Err(e) => refused(StatusCode::INTERNAL_SERVER_ERROR, format!("failed: {e}")),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderRequest {
    view: View,
    stage: Stage,
    /// The view's generation from its first stage; none starts a new view.
    #[serde(default)]
    generation: Option<u64>,
}

async fn render(state: Shared, Json(request): Json<RenderRequest>) -> Response {
    let timeline = state.document.lock().expect("document").timeline.clone();
    let prepared = match request.view.prepare(&timeline) {
        Ok(p) => p,
        Err(message) => return refused(StatusCode::UNPROCESSABLE_ENTITY, message),
    };
    // A first stage, or a playback frame, stops the view's render before it.
    let generation = match request.generation {
        Some(g) => g,
        None => state.renders.begin(),
    };
    let _turn = match request.stage {
        Stage::Play => Some(state.playing.acquire().await),
        _ => None,
    };
    // Playback frames rendering now, this one included (0 for a view).
    let playing = match request.stage {
        Stage::Play => super::PLAYING_AT_ONCE - state.playing.available_permits(),
        _ => 0,
    };
    let shared = state.clone();
    let picture = tokio::task::spawn_blocking(move || {
        shared.renders.render(&prepared, request.stage, generation)
    })
    .await;
    match picture {
        Ok(Some(p)) => (
            [
                (header::CONTENT_TYPE, "image/png".to_string()),
                (
                    header::HeaderName::from_static("x-generation"),
                    generation.to_string(),
                ),
                (
                    header::HeaderName::from_static("x-size"),
                    format!("{}x{}", p.width, p.height),
                ),
                (
                    header::HeaderName::from_static("x-samples"),
                    p.samples.to_string(),
                ),
                (
                    header::HeaderName::from_static("x-seconds"),
                    format!("{:.3}", p.seconds),
                ),
                (
                    header::HeaderName::from_static("x-playing"),
                    playing.to_string(),
                ),
            ],
            p.png,
        )
            .into_response(),
        Ok(None) => refused(StatusCode::CONFLICT, "a newer view replaced this one"),
        Err(e) => refused(
            StatusCode::INTERNAL_SERVER_ERROR,
            format!("render failed: {e}"),
        ),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PickRequest {
    view: View,
    x: u32,
    y: u32,
}

async fn pick(state: Shared, Json(request): Json<PickRequest>) -> Response {
    let timeline = state.document.lock().expect("document").timeline.clone();
    let prepared = match request.view.prepare(&timeline) {
        Ok(p) => p,
        Err(message) => return refused(StatusCode::UNPROCESSABLE_ENTITY, message),
    };
    let (w, h) = (prepared.width, prepared.height);
    if request.x >= w || request.y >= h {
        let message = format!("pixel ({}, {}) is outside {w}x{h}", request.x, request.y);
        return refused(StatusCode::UNPROCESSABLE_ENTITY, message);
    }
    let report = tokio::task::spawn_blocking(move || {
        let scene = &prepared.scenes[0];
        crate::render::pick::pick(scene, prepared.frame, [request.x, request.y], [w, h])
    })
    .await;
    match report {
        Ok(report) => Json(report).into_response(),
        Err(e) => refused(
            StatusCode::INTERNAL_SERVER_ERROR,
            format!("pick failed: {e}"),
        ),
    }
}

async fn estimate(state: Shared, Json(view): Json<View>) -> Response {
    let timeline = state.document.lock().expect("document").timeline.clone();
    let prepared = match view.prepare(&timeline) {
        Ok(p) => p,
        Err(message) => return refused(StatusCode::UNPROCESSABLE_ENTITY, message),
    };
    let estimate =
        tokio::task::spawn_blocking(move || super::renderer::estimate(&timeline, &prepared)).await;
    match estimate {
        Ok(e) => Json(e).into_response(),
        Err(e) => refused(
            StatusCode::INTERNAL_SERVER_ERROR,
            format!("estimate failed: {e}"),
        ),
    }
}

/// An edit as the page sends it (`timeline::edit::Edit`, values as lists).
#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum EditRequest {
    SetScene {
        parameter: String,
        value: Vec<Component>,
    },
    SetKey {
        track: String,
        time: f64,
        value: Vec<Component>,
    },
    DeleteKey {
        track: String,
        index: usize,
    },
    MoveKey {
        track: String,
        index: usize,
        time: f64,
    },
}

impl EditRequest {
    fn edit(self) -> Result<crate::timeline::edit::Edit, String> {
        use crate::timeline::edit::Edit;
        Ok(match self {
            EditRequest::SetScene { parameter, value } => Edit::SetScene {
                value: key_value(&parameter, &value)?,
                parameter,
            },
            EditRequest::SetKey { track, time, value } => Edit::SetKey {
                value: key_value(&track, &value)?,
                track,
                time,
            },
            EditRequest::DeleteKey { track, index } => Edit::DeleteKey { track, index },
            EditRequest::MoveKey { track, index, time } => Edit::MoveKey { track, index, time },
        })
    }
}

/// A value as the page sends it: one number or three, where a point that
/// takes digits (`parameters::Exact`) may have strings of digits among them.
fn key_value(name: &str, value: &[Component]) -> Result<crate::timeline::KeyValue, String> {
    use crate::timeline::KeyValue;
    let digits = value.iter().any(|c| matches!(c, Component::Digits(..)));
    let takes = crate::timeline::parameters::find(name).is_some_and(|p| p.digits.is_some());
    match value {
        [_] | [_, _, _] if digits && !takes => Err(format!("{name}: {NOT_DIGITS}")),
        [x, y, z] if digits => Ok(KeyValue::Digits(Coordinates::from_components([
            x.clone(),
            y.clone(),
            z.clone(),
        ]))),
        [v] => Ok(KeyValue::Number(v.value())),
        [x, y, z] => Ok(KeyValue::Triple(x.value(), y.value(), z.value())),
        _ => Err(format!(
            "{name}: a value is one number or three, got {}",
            value.len()
        )),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EditsRequest {
    edits: Vec<EditRequest>,
}

async fn edit(state: Shared, Json(request): Json<EditsRequest>) -> Response {
    if request.edits.len() > super::document::MAX_EDITS {
        let message = format!("at most {} edits at once", super::document::MAX_EDITS);
        return refused(StatusCode::UNPROCESSABLE_ENTITY, message);
    }
    let edits: Result<Vec<_>, String> = request.edits.into_iter().map(EditRequest::edit).collect();
    // Checked without the document's lock, which every route takes.
    let _turn = state.editing.lock().await;
    let (base, shown) = state.document.lock().expect("document").snapshot();
    let result = tokio::task::spawn_blocking(move || {
        let made = super::document::edited(&base, &shown, &edits?);
        made.map(|made| (base, made))
    })
    .await;
    let (base, made) = match result {
        Ok(Ok(done)) => done,
        Ok(Err(message)) => return refused(StatusCode::UNPROCESSABLE_ENTITY, message),
        Err(e) => return refused(StatusCode::INTERNAL_SERVER_ERROR, format!("failed: {e}")),
    };
    let mut document = state.document.lock().expect("document");
    match document.put_edited(&base, made) {
        Ok(()) => Json(state_of(&document)).into_response(),
        Err(message) => refused(StatusCode::CONFLICT, message),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SaveRequest {
    /// A new file in the timeline's folder; none saves the timeline itself.
    #[serde(default)]
    name: Option<String>,
    /// Write over the file though it changed on disk since it was read.
    #[serde(default)]
    overwrite: bool,
}

async fn save(state: Shared, Json(request): Json<SaveRequest>) -> Response {
    with_document(state.0, move |document| {
        // Looked at under the same lock as the write, just before it.
        if request.name.is_none() && !request.overwrite && document.changed_on_disk() {
            let message = "the file changed on disk since it was read: Reload takes it in, Save as writes a new file, or save again to write over it";
            return Err((StatusCode::CONFLICT, message.into()));
        }
        let saved = document.save(request.name.as_deref());
        saved.map(drop).map_err(unprocessable)
    })
    .await
}

async fn reload(state: Shared) -> Response {
    with_document(state.0, |document| document.reload().map_err(unprocessable)).await
}

fn unprocessable(message: String) -> (StatusCode, String) {
    (StatusCode::UNPROCESSABLE_ENTITY, message)
}

/// Runs `change` on the document off the async threads (it reads and
/// writes files), and answers with the new state or the refusal.
async fn with_document(
    state: Arc<State>,
    change: impl FnOnce(&mut super::Document) -> Result<(), (StatusCode, String)> + Send + 'static,
) -> Response {
    let answer = tokio::task::spawn_blocking(move || {
        let mut document = state.document.lock().expect("document");
        change(&mut document).map(|()| state_of(&document))
    })
    .await;
    match answer {
        Ok(Ok(shown)) => Json(shown).into_response(),
        Ok(Err((status, message))) => refused(status, message),
        Err(e) => refused(StatusCode::INTERNAL_SERVER_ERROR, format!("failed: {e}")),
    }
}

/// File changes and render progress, as they happen.
async fn events(state: Shared) -> Response {
    let events = state.events.subscribe();
    let stream = futures_util::stream::unfold(events, |mut events| async move {
        loop {
            match events.recv().await {
                Ok(event) => {
                    let data = serde_json::to_string(&event).unwrap_or_default();
                    let sse = axum::response::sse::Event::default().data(data);
                    return Some((Ok::<_, std::convert::Infallible>(sse), events));
                }
                Err(tokio::sync::broadcast::error::RecvError::Lagged(_)) => continue,
                Err(_) => return None,
            }
        }
    });
    Sse::new(stream)
        .keep_alive(KeepAlive::default())
        .into_response()
}

/// Sends `event` to every page listening.
pub fn announce(state: &State, event: Event) {
    let _ = state.events.send(event);
}
