//! # nesy-view
//!
//! Seeing what a run did, in a browser. [`Page`] and [`Html`] build the self-contained HTML
//! reports that `nesy adapt` and `nesy bench` write into their run directories: every piece of
//! text (a model's reply, a file name) is escaped on the way in, pictures are embedded as
//! `data:` URIs, and a page runs no script and loads nothing from the network. [`serve`]
//! is the read-only server behind `nesy serve`: it answers with the files under one folder
//! and never with anything outside it.
//!
//! ```
//! use nesy_view::{Html, Page};
//!
//! let mut page = Page::new("run 1");
//! page.section(
//!     "verdict",
//!     "Verdict",
//!     Html::tag("p", "bad", Html::text("unresolved: (Open drawer) <never> held")),
//! );
//! let document = page.finish();
//! assert!(document.contains("&lt;never&gt;"));
//! assert!(!document.contains("<script"));
//! ```

mod html;
mod serve;

pub use html::{Html, Page, escape};
pub use serve::{Folder, REPORT_FILE, Refusal, Resolved, ServeError, serve};
