//! # nesy-vlm
//!
//! The client through which every NeSyCR step that thinks talks to a vision-language
//! model: an OpenAI-compatible chat-completions client with backend profiles, retries,
//! accounting and cassette record/replay.
