//! The vocabulary file: a task's own predicates and object kinds, written by hand in TOML.
//!
//! ```toml
//! format_version = 1
//! builtin = true            # keep the benchmark's fifteen predicates (the default)
//!
//! [[kinds]]
//! name = "parts"
//! meaning = "many small loose pieces handled together"
//!
//! [[predicates]]
//! name = "Finegrained"
//! params = ["x - parts"]    # `name` or `name - kind`; the kind defaults to `thing`
//! meaning = "?x consists of many small loose parts."
//!
//! [[predicates]]
//! name = "Gathered"
//! params = ["x"]
//! category = "physics"      # or `embodiment` (never part of a goal); default physics
//! meaning = "the parts of ?x lie together in one pile."
//!
//! [objects]                 # optional: kinds of named objects (others take any parameter)
//! black_screws = "parts"
//! ```
//!
//! With `builtin = false` the file's predicates are the whole vocabulary. Redeclaring a
//! built-in with its own arity replaces its meaning; any other arity is an error, and so is
//! a predicate declared twice in the file, a meaning that mentions a parameter the
//! predicate does not have, or a kind used before it is declared. Every error names the
//! line and the field.

use serde::Deserialize;

use crate::predicates::{Category, PredicateInfo, Vocabulary, VocabularyError};
use crate::symbol::Symbol;
use crate::types::ROOT_TYPE;

/// The vocabulary file format version this build reads.
pub const VOCABULARY_FORMAT_VERSION: u32 = 1;

/// Most parameters a declared predicate may have.
pub const MAX_PREDICATE_ARITY: usize = 6;

/// Why a vocabulary file was not accepted: where (line, column, field) and what was
/// expected. The caller adds the file's path.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: {field}: {message}")]
pub struct VocabularyFileError {
    /// 1-based line of the offending value.
    pub line: usize,
    /// 1-based column of the offending value.
    pub column: usize,
    /// The field, e.g. `predicates[1].params[0]` (`.` for the whole document).
    pub field: String,
    /// What was wrong and what was expected.
    pub message: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRepr {
    format_version: toml::Spanned<u32>,
    #[serde(default = "default_builtin")]
    builtin: bool,
    #[serde(default)]
    kinds: Vec<KindRepr>,
    #[serde(default)]
    predicates: Vec<PredicateRepr>,
    #[serde(default)]
    objects: std::collections::BTreeMap<String, toml::Spanned<String>>,
}

fn default_builtin() -> bool {
    true
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KindRepr {
    name: toml::Spanned<String>,
    #[serde(default)]
    parent: Option<toml::Spanned<String>>,
    #[serde(default)]
    meaning: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PredicateRepr {
    name: toml::Spanned<String>,
    #[serde(default)]
    params: Option<toml::Spanned<Vec<toml::Spanned<String>>>>,
    #[serde(default)]
    category: Option<toml::Spanned<String>>,
    meaning: toml::Spanned<String>,
}

/// Words the formula reader takes as connectives: never a predicate's name.
const RESERVED: &[&str] = &["and", "or", "not", "imply", "forall", "exists", "when"];

/// Reads a vocabulary file's text (see the module documentation for the format).
///
/// ```
/// use nesy_core::{Symbol, parse_vocabulary_file};
///
/// let text = "format_version = 1\n[[predicates]]\nname = \"Gathered\"\nparams = [\"x\"]\nmeaning = \"the parts of ?x lie together.\"\n";
/// let vocabulary = parse_vocabulary_file(text).unwrap();
/// assert!(vocabulary.get(Symbol::new("Gathered")).is_some());
/// assert!(vocabulary.get(Symbol::new("OnTopOf")).is_some());
///
/// let twice = format!("{text}[[predicates]]\nname = \"Gathered\"\nparams = [\"x\"]\nmeaning = \"again\"\n");
/// let error = parse_vocabulary_file(&twice).unwrap_err();
/// assert_eq!(error.line, 7);
/// assert_eq!(error.field, "predicates[1].name");
/// ```
pub fn parse_vocabulary_file(text: &str) -> Result<Vocabulary, VocabularyFileError> {
    let at = |span: std::ops::Range<usize>, field: String, message: String| {
        let (line, column) = line_column(text, span.start);
        VocabularyFileError {
            line,
            column,
            field,
            message,
        }
    };
    let repr: FileRepr = {
        let de = toml::Deserializer::parse(text)
            .map_err(|e| at(e.span().unwrap_or(0..0), ".".to_string(), e.message().to_string()))?;
        serde_path_to_error::deserialize(de).map_err(|e| {
            let field = e.path().to_string();
            let inner = e.into_inner();
            at(inner.span().unwrap_or(0..0), field, inner.message().to_string())
        })?
    };
    if *repr.format_version.get_ref() != VOCABULARY_FORMAT_VERSION {
        return Err(at(
            repr.format_version.span(),
            "format_version".into(),
            format!(
                "expected {VOCABULARY_FORMAT_VERSION}, found {}",
                repr.format_version.get_ref()
            ),
        ));
    }
    let mut vocabulary = if repr.builtin {
        Vocabulary::new()
    } else {
        Vocabulary::empty()
    };
    for (i, kind) in repr.kinds.iter().enumerate() {
        let field = format!("kinds[{i}].name");
        check_name(kind.name.get_ref(), false).map_err(|m| at(kind.name.span(), field.clone(), m))?;
        let (parent, parent_span) = match &kind.parent {
            Some(p) => (p.get_ref().as_str(), p.span()),
            None => (ROOT_TYPE, kind.name.span()),
        };
        vocabulary
            .declare_kind(kind.name.get_ref(), parent, &kind.meaning)
            .map_err(|e| match e {
                VocabularyError::UnknownKind { .. } => at(
                    parent_span,
                    format!("kinds[{i}].parent"),
                    format!("{e}; declare a parent before its children"),
                ),
                other => at(kind.name.span(), field.clone(), other.to_string()),
            })?;
    }
    let mut declared: Vec<&str> = Vec::new();
    for (i, predicate) in repr.predicates.iter().enumerate() {
        let name = predicate.name.get_ref().as_str();
        let name_field = format!("predicates[{i}].name");
        check_name(name, true).map_err(|m| at(predicate.name.span(), name_field.clone(), m))?;
        if declared.contains(&name) {
            return Err(at(
                predicate.name.span(),
                name_field,
                format!("predicate `{name}` is declared twice in this file"),
            ));
        }
        declared.push(name);
        let (params, params_span) = match &predicate.params {
            Some(p) => (p.get_ref().as_slice(), p.span()),
            None => (&[][..], predicate.name.span()),
        };
        if params.len() > MAX_PREDICATE_ARITY {
            return Err(at(
                params_span,
                format!("predicates[{i}].params"),
                format!(
                    "expected at most {MAX_PREDICATE_ARITY} parameters, found {}",
                    params.len()
                ),
            ));
        }
        let mut names: Vec<String> = Vec::with_capacity(params.len());
        let mut kinds: Vec<Symbol> = Vec::with_capacity(params.len());
        for (j, param) in params.iter().enumerate() {
            let field = format!("predicates[{i}].params[{j}]");
            let (param_name, kind) =
                split_param(param.get_ref()).map_err(|m| at(param.span(), field.clone(), m))?;
            if names.iter().any(|n| n == param_name) {
                return Err(at(
                    param.span(),
                    field,
                    format!("parameter `{param_name}` appears twice"),
                ));
            }
            let kind = Symbol::new(kind);
            if let Err(e) = vocabulary.check_kind(kind) {
                return Err(at(param.span(), field, e.to_string()));
            }
            names.push(param_name.to_string());
            kinds.push(kind);
        }
        let meaning = predicate.meaning.get_ref().trim();
        let meaning_field = format!("predicates[{i}].meaning");
        if meaning.is_empty() || meaning.contains('\n') {
            return Err(at(
                predicate.meaning.span(),
                meaning_field,
                "expected a one-line meaning for the prompt".into(),
            ));
        }
        if let Some(stray) = mentioned_params(meaning).find(|m| !names.iter().any(|n| n == m)) {
            return Err(at(
                predicate.meaning.span(),
                meaning_field,
                format!(
                    "the meaning mentions ?{stray}, which is not a parameter of `{name}` (parameters: {})",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names
                            .iter()
                            .map(|n| format!("?{n}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
            ));
        }
        let category = match &predicate.category {
            None => Category::Physics,
            Some(c) => match c.get_ref().as_str() {
                "physics" => Category::Physics,
                "embodiment" => Category::Embodiment,
                other => {
                    return Err(at(
                        c.span(),
                        format!("predicates[{i}].category"),
                        format!("expected `physics` or `embodiment`, found `{other}`"),
                    ));
                }
            },
        };
        let all_root = kinds.iter().all(|k| k.as_str() == ROOT_TYPE);
        vocabulary
            .declare_predicate(PredicateInfo {
                name: Symbol::new(name),
                arity: names.len(),
                category,
                params: names,
                definition: meaning.to_string(),
                tiers: Vec::new(),
                kinds: if all_root { Vec::new() } else { kinds },
            })
            .map_err(|e| at(predicate.name.span(), name_field, e.to_string()))?;
    }
    for (object, kind) in &repr.objects {
        vocabulary
            .assign_kind(object, kind.get_ref())
            .map_err(|e| at(kind.span(), format!("objects.{object}"), e.to_string()))?;
    }
    if vocabulary.predicates().is_empty() {
        return Err(at(
            0..0,
            "predicates".into(),
            "expected at least one predicate (or `builtin = true`)".into(),
        ));
    }
    Ok(vocabulary)
}

/// 1-based line and column of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// A predicate or kind name: an ASCII letter, then letters, digits or `_`.
fn check_name(name: &str, predicate: bool) -> Result<(), String> {
    let what = if predicate { "predicate" } else { "kind" };
    let mut bytes = name.bytes();
    let starts_with_letter = bytes.next().is_some_and(|b| b.is_ascii_alphabetic());
    if !starts_with_letter || !bytes.all(|b| b.is_ascii_alphanumeric() || b == b'_') {
        return Err(format!(
            "expected a {what} name of ASCII letters, digits and `_`, starting with a letter; found `{name}`"
        ));
    }
    if RESERVED.iter().any(|r| r.eq_ignore_ascii_case(name)) {
        return Err(format!(
            "`{name}` is a connective of the formula language, not a {what} name"
        ));
    }
    Ok(())
}

/// `x` or `x - parts` (a leading `?` is accepted) into the name and the kind.
fn split_param(text: &str) -> Result<(&str, &str), String> {
    let (name, kind) = match text.split_once(" - ") {
        Some((n, k)) => (n.trim(), k.trim()),
        None => (text.trim(), ROOT_TYPE),
    };
    let name = name.strip_prefix('?').unwrap_or(name);
    let good = |s: &str| {
        s.bytes().next().is_some_and(|b| b.is_ascii_alphabetic())
            && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
    };
    if !good(name) || !good(kind) {
        return Err(format!(
            "expected `name` or `name - kind` (letters, digits and `_`), found `{text}`"
        ));
    }
    Ok((name, kind))
}

/// The parameter names a meaning mentions as `?name`.
fn mentioned_params(meaning: &str) -> impl Iterator<Item = &str> {
    meaning.split('?').skip(1).filter_map(|rest| {
        let end = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        (end > 0).then(|| &rest[..end])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Atom;

    const FILE: &str = r#"format_version = 1

[[kinds]]
name = "parts"

[[kinds]]
name = "screws"
parent = "parts"

[[predicates]]
name = "Finegrained"
params = ["x - parts"]
meaning = "?x consists of many small loose parts."

[[predicates]]
name = "Gathered"
params = ["x"]
meaning = "the parts of ?x lie together in one pile."

[objects]
black_screws = "screws"
tray = "thing"
"#;

    fn error(text: &str) -> VocabularyFileError {
        parse_vocabulary_file(text).unwrap_err()
    }

    #[test]
    fn declarations_extend_the_builtins_with_kinds() {
        let v = parse_vocabulary_file(FILE).unwrap();
        assert_eq!(v.predicates().len(), 17);
        let fine = v.get(Symbol::new("Finegrained")).unwrap();
        assert_eq!(
            fine.definition_line(),
            "(Finegrained ?x - parts): ?x consists of many small loose parts."
        );
        assert!(v.check_atom(&Atom::new("Finegrained", &["black_screws"])).is_ok());
        assert!(v.check_atom(&Atom::new("Finegrained", &["unnamed_heap"])).is_ok());
        let wrong = v.check_atom(&Atom::new("Finegrained", &["tray"])).unwrap_err();
        assert_eq!(
            wrong.to_string(),
            "argument 1 of `Finegrained` must be a `parts`, but `tray` is a `thing`"
        );
        assert_eq!(
            v.get(Symbol::new("Gathered")).unwrap().definition_line(),
            "(Gathered ?x): the parts of ?x lie together in one pile."
        );
    }

    #[test]
    fn without_builtins_only_the_file_counts() {
        let v =
            parse_vocabulary_file(&FILE.replace("format_version = 1", "format_version = 1\nbuiltin = false"))
                .unwrap();
        assert_eq!(v.predicates().len(), 2);
        assert!(v.get(Symbol::new("OnTopOf")).is_none());
        let none = error("format_version = 1\nbuiltin = false\n");
        assert_eq!(none.field, "predicates");
    }

    #[test]
    fn errors_name_the_line_and_field() {
        let bad_arity = error(
            "format_version = 1\n[[predicates]]\nname = \"OnTopOf\"\nparams = [\"a\"]\nmeaning = \"?a is up.\"\n",
        );
        assert_eq!(
            (bad_arity.line, bad_arity.field.as_str()),
            (3, "predicates[0].name")
        );
        assert!(bad_arity.message.contains("arity 2"), "{bad_arity}");

        let stray = error(
            "format_version = 1\n[[predicates]]\nname = \"Near\"\nparams = [\"a\"]\nmeaning = \"?a is near ?b.\"\n",
        );
        assert_eq!((stray.line, stray.field.as_str()), (5, "predicates[0].meaning"));
        assert!(stray.message.contains("?b"), "{stray}");

        let kind = error(
            "format_version = 1\n[[predicates]]\nname = \"Near\"\nparams = [\"a - tool\"]\nmeaning = \"?a is near.\"\n",
        );
        assert_eq!(kind.field, "predicates[0].params[0]");
        assert!(kind.message.contains("unknown object kind `tool`"), "{kind}");

        let unknown_field =
            error("format_version = 1\n[[predicates]]\nname = \"Near\"\nparms = [\"a\"]\nmeaning = \"x\"\n");
        assert_eq!(unknown_field.line, 4, "{unknown_field}");

        let syntax = error("format_version = 1\n[[predicates]\n");
        assert_eq!(syntax.line, 2, "{syntax}");

        let version = error("format_version = 2\n");
        assert_eq!(version.field, "format_version");

        let keyword = error("format_version = 1\n[[predicates]]\nname = \"forall\"\nmeaning = \"x\"\n");
        assert!(keyword.message.contains("connective"), "{keyword}");

        let object = error("format_version = 1\n[objects]\nbolt = \"parts\"\n");
        assert_eq!((object.line, object.field.as_str()), (3, "objects.bolt"));
    }

    proptest::proptest! {
        /// Any edit of a valid file (a byte range replaced by arbitrary text) is a
        /// vocabulary or an error whose line lies in the edited text; never a panic.
        #[test]
        fn edited_files_never_panic(start in 0usize..400, len in 0usize..40, insert in "\\PC{0,24}") {
            let start = start.min(FILE.len());
            let end = (start + len).min(FILE.len());
            let (start, end) = (floor_char(FILE, start), floor_char(FILE, end));
            let text = format!("{}{}{}", &FILE[..start], insert, &FILE[end..]);
            if let Err(e) = parse_vocabulary_file(&text) {
                proptest::prop_assert!(e.line >= 1 && e.line <= text.lines().count().max(1) + 1, "{e}");
            }
        }
    }

    fn floor_char(text: &str, mut at: usize) -> usize {
        while !text.is_char_boundary(at) {
            at -= 1;
        }
        at
    }

    #[test]
    fn meanings_mention_parameters() {
        let found: Vec<&str> = mentioned_params("?x lies on ?floor_2, not ?.").collect();
        assert_eq!(found, ["x", "floor_2"]);
    }
}
