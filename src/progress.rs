//! Progress of long builds (the quintic's solve takes minutes on a real model), for a front end
//! to show: the library names the step it is in; nothing is shown unless a front end installs
//! a sink (the CLI's spinner on a terminal). Messages never change a result.

use std::sync::RwLock;

/// Receives each step's message.
pub type Sink = Box<dyn Fn(&str) + Send + Sync>;

static SINK: RwLock<Option<Sink>> = RwLock::new(None);

/// Installs `sink` (or removes it with `None`) for the whole process.
pub fn set_sink(sink: Option<Sink>) {
    *SINK
        .write()
        .unwrap_or_else(std::sync::PoisonError::into_inner) = sink;
}

/// Tells the sink, if there is one, that the step `msg` begins (the message is only made
/// when a sink listens).
pub fn report(msg: impl FnOnce() -> String) {
    let guard = SINK
        .read()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(sink) = guard.as_ref() {
        sink(&msg());
    }
}
