//! # pdyn-web — pdyn in a browser tab
//!
//! The third front end, beside the binary and Python: wasm-bindgen exports that take a model
//! file's text and options as JSON, call the same library entries as `pdyn run`, `derive`,
//! `forces`, `check` and `sweep` (`pdyn::run`, `pdyn::report::*`), or a script of `pdyn kin`
//! and `pdyn dsolve` command lines (`script.rs`), and return JSON: on
//! success `{"ok": true, …}` with the command's own text and JSON output, on failure the
//! CLI's `{"error": {kind, message, location: {file, line, column}, exit_code}}`. Nothing
//! here computes: it converts. Built for `wasm32-unknown-unknown` (scripts/build-web.sh),
//! where `pdyn-jit` interprets (the CLI's `--no-jit`, bit for bit) and rayon runs on the
//! calling thread; natively it builds and is tested like any crate.

mod options;
mod script;
mod tables;

use options::Options;
use pdyn::model_file::ModelFile;
use pdyn::options::{name_options_as, Naming};
use pdyn::{Error, Progress};
use serde_json::{json, Value};
use std::cell::RefCell;
use wasm_bindgen::prelude::*;

thread_local! {
    /// The message of the last panic (an internal error): a panic aborts the WebAssembly
    /// instance, and the page reads this through [`take_panic`] before starting a new one.
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Called once when the module is instantiated: options named as the CLI's flags (the page
/// mirrors the command line), the page's clock for reported times, and the panic message
/// kept for [`take_panic`].
#[wasm_bindgen(start)]
pub fn start() {
    name_options_as(Naming::Flags);
    #[cfg(target_arch = "wasm32")]
    pdyn::clock::set_source(now_ms);
    std::panic::set_hook(Box::new(|info| {
        let message = format!("internal error in pdyn (please report it): {info}");
        LAST_PANIC.with(|p| *p.borrow_mut() = Some(message));
    }));
}

#[cfg(target_arch = "wasm32")]
#[wasm_bindgen]
extern "C" {
    /// `performance.now()`, in a page and in a worker alike.
    #[wasm_bindgen(js_namespace = performance, js_name = now)]
    fn now_ms() -> f64;
}

/// The message of the panic that stopped the last call, if one did.
#[wasm_bindgen]
pub fn take_panic() -> Option<String> {
    LAST_PANIC.with(|p| p.borrow_mut().take())
}

/// pdyn's version.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// The model file's kind: `{"ok": true, "kind": "mechanics" | "nbody" | "md"}`.
#[wasm_bindgen]
pub fn kind(source: &str, origin: &str) -> String {
    let file = ModelFile::from_source(source.to_string(), origin.to_string());
    ok(json!({"kind": file.kind.name()}))
}

/// `pdyn run MODEL --no-jit --json`: `summary` (what `--json` prints), `report` (the text),
/// `warnings`, and the data the page plots and animates (`tables::of`). `on_progress(done,
/// all)` is called as an MD run goes (a worker posts it to the page).
#[wasm_bindgen]
pub fn run(
    source: &str,
    origin: &str,
    options: &str,
    on_progress: Option<js_sys::Function>,
) -> String {
    answer(|| {
        let file = ModelFile::from_source(source.to_string(), origin.to_string());
        let opts = Options::parse(options)?;
        let req = opts.request()?;
        let mut frames = tables::Frames::new(opts.max_frames);
        let mut total = 0u64;
        let report = ProgressFn(on_progress);
        let mut progress = |p: Progress| match p {
            Progress::Started { steps, .. } => total = steps,
            Progress::Step(done) => report.call(done as f64, total as f64),
            Progress::Frame { time, x, y, z } => frames.push(time, x, y, z),
            _ => {}
        };
        let output = pdyn::run(&file, &req, &mut progress)?;
        let mut v = tables::of(&output, frames);
        v["summary"] = output.summary().clone();
        v["summary_text"] = output.summary_text().into();
        v["report"] = output.report(None).into();
        v["warnings"] = json!(output.warnings());
        v["failure"] = output
            .failure()
            .map(|f| f.to_json()["error"].clone())
            .into();
        Ok(v)
    })
}

/// `pdyn derive MODEL [--latex] [--json]`: `text` (the printed derivation) and, with
/// `"json": true`, `derivation` (every expression as text and LaTeX).
#[wasm_bindgen]
pub fn derive(source: &str, origin: &str, options: &str) -> String {
    answer(|| {
        let opts = Options::parse(options)?;
        let model = opts.mechanics(source, origin)?;
        let req = opts.derive_request()?;
        let text = pdyn::report::derive::report(model, &req)?;
        if req.json {
            let parsed: Value = serde_json::from_str(&text).map_err(|e| Error::Internal {
                message: format!("derive --json printed what is not JSON: {e}"),
            })?;
            Ok(json!({"derivation": parsed}))
        } else {
            Ok(json!({"text": text}))
        }
    })
}

/// `pdyn forces MODEL --at … [--json]`.
#[wasm_bindgen]
pub fn forces(source: &str, origin: &str, options: &str) -> String {
    answer(|| {
        let opts = Options::parse(options)?;
        let model = opts.mechanics(source, origin)?;
        let text = pdyn::report::forces::report(model, &opts.forces_request()?)?;
        opts.text_or_json(text)
    })
}

/// `pdyn check MODEL --no-jit [--json]`: the run against the closed form.
#[wasm_bindgen]
pub fn check(source: &str, origin: &str, options: &str) -> String {
    answer(|| {
        let opts = Options::parse(options)?;
        let model = opts.mechanics(source, origin)?;
        let rep = pdyn::report::check::report(model, &opts.request()?, opts.json)?;
        let mut v = opts.text_or_json(rep.stdout)?;
        v["failure"] = rep.failure.map(|f| f.to_json()["error"].clone()).into();
        Ok(v)
    })
}

/// `pdyn sweep MODEL --no-jit [--json]`, the runs one after the other; `on_progress(done,
/// all)` after each.
#[wasm_bindgen]
pub fn sweep(
    source: &str,
    origin: &str,
    options: &str,
    on_progress: Option<js_sys::Function>,
) -> String {
    answer(|| {
        let opts = Options::parse(options)?;
        let model = opts.mechanics(source, origin)?;
        let progress = ProgressFn(on_progress);
        let on_run = |done: usize, all: usize| progress.call(done as f64, all as f64);
        let rep = pdyn::report::sweep::report(model, &opts.request()?, None, opts.json, &on_run)?;
        let mut v = opts.text_or_json(rep.stdout)?;
        v["warnings"] = rep
            .stderr
            .lines()
            .map(str::to_string)
            .collect::<Vec<_>>()
            .into();
        Ok(v)
    })
}

/// A script of `pdyn kin …` and `pdyn dsolve …` lines (`examples/kin/*.sh`), run line by
/// line: `{"commands": [{line, command, name, text, result}]}`, each with the text and the
/// JSON the CLI prints for it. The first failing line stops the script; its error is located
/// at the word that caused it (`location: {file: origin, line, column}`).
#[wasm_bindgen]
pub fn commands(script: &str, origin: &str) -> String {
    match script::run(script) {
        Ok(commands) => ok(json!({ "commands": commands })),
        Err(e) => {
            let mut v = e.error.to_json();
            v["error"]["location"] = json!({"file": origin, "line": e.line, "column": e.column});
            v["ok"] = false.into();
            v["text"] = format!("{origin}:{}:{}: {}", e.line, e.column, e.error).into();
            v.to_string()
        }
    }
}

/// Whether a text is a script of command lines (true) or a model file.
#[wasm_bindgen]
pub fn is_script(text: &str) -> bool {
    script::is_script(text)
}

/// `pdyn run MODEL --method help`: the methods for the model's kind.
#[wasm_bindgen]
pub fn methods_help(source: &str, origin: &str) -> String {
    let file = ModelFile::from_source(source.to_string(), origin.to_string());
    ok(json!({"text": pdyn::engine::methods_help(file.kind)}))
}

/// The page's progress callback. A sweep's callback must be `Sync` (rayon), and a
/// WebAssembly build without threads runs it on the one thread there is.
struct ProgressFn(Option<js_sys::Function>);

// SAFETY: `wasm32-unknown-unknown` without the atomics feature has one thread: the callback is
// never called from another. Natively (tests) it is always `None`.
unsafe impl Sync for ProgressFn {}

impl ProgressFn {
    /// `on_progress(done, all)`; an exception thrown by the page's callback is its own.
    fn call(&self, done: f64, all: f64) {
        if let Some(f) = &self.0 {
            let _ = f.call2(&JsValue::NULL, &done.into(), &all.into());
        }
    }
}

/// `{"ok": true, …fields}`.
fn ok(mut v: Value) -> String {
    v["ok"] = true.into();
    v.to_string()
}

/// Runs `f` and renders its result or its error as the CLI's JSON does.
fn answer(f: impl FnOnce() -> Result<Value, Error>) -> String {
    match f() {
        Ok(v) => ok(v),
        Err(e) => {
            let mut v = e.to_json();
            v["ok"] = false.into();
            v["text"] = e.to_string().into();
            v.to_string()
        }
    }
}
