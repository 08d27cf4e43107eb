//! The grammar each reply must follow, built from what the call already knows: the
//! predicates of the prompt's tier with their arities, the objects of the scene, and (for a
//! patch) the actions of the current procedure. Sent to servers that can hold generation to
//! a grammar ([`nesy_vlm::ReplyConstraint`]), it keeps even a weak model inside the layout
//! the parsers read; the parsers, the verifier and the re-ask budgets stay as they are.
//!
//! Every grammar bounds its free text (rationale lines, action names) and its lists, so a
//! constrained reply cannot run away.
//!
//! Backends that hold replies only to JSON (OpenAI's `response_format`, Ollama's `format`)
//! get the same answer as a JSON schema with the same symbols and bounds; the reply they
//! send back is written out in the prompt's layout again ([`induction_layout`],
//! [`patch_layout`], [`translation_layout`]) before the usual parser reads it.

use std::fmt::Write as _;

use nesy_core::adapt::TaskContext;
use nesy_core::{Operator, State, Tier, Vocabulary};
use nesy_vlm::{ReplyConstraint, gbnf_literal};
use serde_json::{Map, Value, json};

/// The most rationale lines a constrained reply may write.
const RATIONALE_LINES: usize = 4;
/// The longest rationale line or action semantic, in characters.
const LINE_CHARS: usize = 200;
/// The most preconditions or effects an action block may list.
const LITERALS_PER_SECTION: usize = 12;
/// The most atoms a translated state may list.
const ATOMS_PER_STATE: usize = 48;
/// The most actions a patch may put in place of the ones it replaces.
const REPLACEMENT_ACTIONS: usize = 6;
/// The most consecutive actions the SEARCH side of a patch may quote.
const SEARCH_SPAN: usize = 8;

/// The symbols a reply may use: predicates by arity and the objects it may name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Symbols {
    predicates: Vec<(String, usize)>,
    objects: Vec<String>,
}

impl Symbols {
    /// The predicates of `tier` in `vocabulary`, and `objects` plus every object the
    /// `states` mention, each once, in order.
    pub fn new<'a>(
        vocabulary: &Vocabulary,
        tier: Tier,
        objects: impl IntoIterator<Item = &'a str>,
        states: impl IntoIterator<Item = &'a State>,
    ) -> Symbols {
        let predicates = vocabulary
            .tier(tier)
            .iter()
            .map(|p| (p.name.as_str().to_owned(), p.arity))
            .collect();
        let mut names: Vec<String> = Vec::new();
        let mut add = |name: &str| {
            if !names.iter().any(|n| n == name) {
                names.push(name.to_owned());
            }
        };
        objects.into_iter().for_each(&mut add);
        for state in states {
            for atom in state.iter() {
                atom.args().iter().for_each(|a| add(a.as_str()));
            }
        }
        Symbols {
            predicates,
            objects: names,
        }
    }

    /// The task's predicates and objects, with those of `states`.
    pub fn of_task<'a>(task: &'a TaskContext, states: impl IntoIterator<Item = &'a State>) -> Symbols {
        Symbols::new(
            &task.vocabulary,
            task.tier,
            task.objects.iter().map(|o| o.as_str()),
            states,
        )
    }

    /// The GBNF rules of literals over these symbols: `atom`, `literal` (an atom, its
    /// negation, or a quantified literal over `?x`) and their parts.
    fn literal_rules(&self) -> String {
        let mut rules = String::new();
        let arities = {
            let mut a: Vec<usize> = self.predicates.iter().map(|(_, n)| *n).collect();
            a.sort_unstable();
            a.dedup();
            a
        };
        let mut heads = Vec::new();
        let mut quantified_heads = Vec::new();
        for arity in &arities {
            let names: Vec<String> = self
                .predicates
                .iter()
                .filter(|(_, n)| n == arity)
                .map(|(name, _)| gbnf_literal(name))
                .collect();
            let _ = writeln!(rules, "pred{arity} ::= {}", names.join(" | "));
            heads.push(format!("pred{arity}{}", " \" \" obj".repeat(*arity)));
            quantified_heads.push(format!("pred{arity}{}", " \" \" arg".repeat(*arity)));
        }
        let objects: Vec<String> = if self.objects.is_empty() {
            // No object is known: no atom with arguments can be written, so none may be.
            vec![gbnf_literal("floor")]
        } else {
            self.objects.iter().map(|o| gbnf_literal(o)).collect()
        };
        let _ = writeln!(rules, "obj ::= {}", objects.join(" | "));
        rules.push_str("arg ::= obj | \"?x\"\n");
        let _ = writeln!(rules, "atom ::= \"(\" ({}) \")\"", heads.join(" | "));
        let _ = writeln!(rules, "qatom ::= \"(\" ({}) \")\"", quantified_heads.join(" | "));
        rules.push_str(
            "literal ::= atom | \"(not \" atom \")\" | \"(forall (?x - thing) \" qliteral \")\"\n\
             qliteral ::= qatom | \"(not \" qatom \")\"\n",
        );
        rules
    }
}

impl Symbols {
    /// A regular expression of one atom whose arguments match `arg`.
    fn atom_pattern(&self, arg: &str) -> String {
        let mut arities: Vec<usize> = self.predicates.iter().map(|(_, n)| *n).collect();
        arities.sort_unstable();
        arities.dedup();
        let heads: Vec<String> = arities
            .iter()
            .map(|arity| {
                let names: Vec<String> = self
                    .predicates
                    .iter()
                    .filter(|(_, n)| n == arity)
                    .map(|(name, _)| regex_escape(name))
                    .collect();
                format!("(?:{}){}", names.join("|"), format!(" {arg}").repeat(*arity))
            })
            .collect();
        format!("\\((?:{})\\)", heads.join("|"))
    }

    /// The regular expressions of an object, a grounded atom and a literal (the grammar's
    /// `obj`, `atom` and `literal`), each anchored.
    fn json_patterns(&self) -> (String, String) {
        let objects: Vec<String> = if self.objects.is_empty() {
            vec!["floor".into()]
        } else {
            self.objects.iter().map(|o| regex_escape(o)).collect()
        };
        let obj = format!("(?:{})", objects.join("|"));
        let atom = self.atom_pattern(&obj);
        let qatom = self.atom_pattern(&format!("(?:{obj}|\\?x)"));
        let literal = format!(
            "^(?:{atom}|\\(not {atom}\\)|\\(forall \\(\\?x - thing\\) (?:{qatom}|\\(not {qatom}\\))\\))$"
        );
        (format!("^{atom}$"), literal)
    }
}

/// `text` with the characters a regular expression gives meaning to escaped (only those:
/// ECMAScript, which JSON Schema patterns follow, refuses other escapes under `u`).
fn regex_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if "\\.+*?()|[]{}^$/".contains(c) {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// A JSON object schema whose every property is required and no other is allowed (what
/// OpenAI's strict mode asks for).
fn object_schema(properties: Vec<(&str, Value)>) -> Value {
    let required: Vec<&str> = properties.iter().map(|(k, _)| *k).collect();
    let properties: Map<String, Value> = properties.into_iter().map(|(k, v)| (k.to_owned(), v)).collect();
    json!({"type": "object", "properties": properties, "required": required, "additionalProperties": false})
}

/// An array of `min` to `max` items of `items`.
fn array_schema(items: Value, min: usize, max: usize) -> Value {
    json!({"type": "array", "items": items, "minItems": min, "maxItems": max})
}

/// A string matching `pattern`.
fn pattern_schema(pattern: &str) -> Value {
    json!({"type": "string", "pattern": pattern})
}

/// A bounded line of free text.
fn line_schema() -> Value {
    json!({"type": "string", "minLength": 1, "maxLength": LINE_CHARS})
}

/// An action block: its name, preconditions (possibly none) and effects.
fn block_schema(literal: &str) -> Value {
    object_schema(vec![
        ("name", pattern_schema("^[A-Za-z][A-Za-z0-9_]{0,79}$")),
        (
            "preconditions",
            array_schema(pattern_schema(literal), 0, LITERALS_PER_SECTION),
        ),
        (
            "effects",
            array_schema(pattern_schema(literal), 1, LITERALS_PER_SECTION),
        ),
    ])
}

/// The JSON object of a reply, or `None` when it is not one.
fn json_object(reply: &str) -> Option<Map<String, Value>> {
    match serde_json::from_str::<Value>(reply.trim()).ok()? {
        Value::Object(map) => Some(map),
        _ => None,
    }
}

/// The strings of `field` in `object`, each on one line; `None` when it is not a list of
/// strings.
fn strings(object: &Map<String, Value>, field: &str) -> Option<Vec<String>> {
    object
        .get(field)?
        .as_array()?
        .iter()
        .map(|v| v.as_str().map(|s| s.replace(['\n', '\r'], " ").trim().to_owned()))
        .collect()
}

/// `item` lines after `prefix`, or `none` on a line of its own when there is no item.
fn bullet_lines(out: &mut String, items: &[String], prefix: &str, none: &str) {
    if items.is_empty() {
        let _ = writeln!(out, "{none}");
    }
    for item in items {
        let _ = writeln!(out, "{prefix}{item}");
    }
}

/// The rationale lines every layout opens with, and a bounded line of free text.
fn text_rules() -> String {
    format!("reason ::= \"- \" line \"\\n\"\nline ::= [^\\n]{{1,{LINE_CHARS}}}\n",)
}

/// The operator-induction reply: rationale lines, then the action semantic and its
/// preconditions (or `None`) and effects, one literal per line, over `symbols`.
///
/// ```
/// use nesy_core::{Tier, Vocabulary};
/// use nesy_reasoner::constraints::{Symbols, induction_constraint};
/// let symbols = Symbols::new(&Vocabulary::new(), Tier::Full, ["red_cube"], []);
/// let grammar = induction_constraint(&symbols).grammar;
/// assert!(grammar.starts_with("root ::= \"* Prediction Rationale:\\n\" reason{1,4}"));
/// assert!(grammar.contains("\"red_cube\""));
/// ```
pub fn induction_constraint(symbols: &Symbols) -> ReplyConstraint {
    let mut grammar = format!(
        "root ::= \"* Prediction Rationale:\\n\" reason{{1,{RATIONALE_LINES}}} \
         \"* Predicted Action:\\nAction Semantic:\\n- \" line \"\\nPrecondition:\\n\" pre \"Effect:\\n\" eff\n\
         pre ::= \"None\\n\" | (\"- \" literal \"\\n\"){{1,{LITERALS_PER_SECTION}}}\n\
         eff ::= (\"- \" literal \"\\n\"){{1,{LITERALS_PER_SECTION}}}\n"
    );
    grammar.push_str(&text_rules());
    grammar.push_str(&symbols.literal_rules());
    let (_, literal) = symbols.json_patterns();
    let json_schema = object_schema(vec![
        ("rationale", array_schema(line_schema(), 1, RATIONALE_LINES)),
        ("action_semantic", line_schema()),
        (
            "preconditions",
            array_schema(pattern_schema(&literal), 0, LITERALS_PER_SECTION),
        ),
        (
            "effects",
            array_schema(pattern_schema(&literal), 1, LITERALS_PER_SECTION),
        ),
    ]);
    ReplyConstraint {
        name: "induce".into(),
        grammar,
        json_schema: Some(json_schema),
    }
}

/// An induction reply given as JSON under [`induction_constraint`]'s schema, written out in
/// the prompt's layout; `None` when it is not such an object.
///
/// ```
/// use nesy_reasoner::constraints::induction_layout;
/// let reply = r#"{"rationale": ["The cube was lifted."], "action_semantic": "pick up the cube",
///     "preconditions": [], "effects": ["(GripperHolding red_cube)"]}"#;
/// assert_eq!(
///     induction_layout(reply).unwrap(),
///     "* Prediction Rationale:\n- The cube was lifted.\n* Predicted Action:\nAction Semantic:\n- pick up the cube\nPrecondition:\nNone\nEffect:\n- (GripperHolding red_cube)\n"
/// );
/// assert!(induction_layout("- (GripperHolding red_cube)").is_none());
/// ```
pub fn induction_layout(reply: &str) -> Option<String> {
    let object = json_object(reply)?;
    let rationale = strings(&object, "rationale")?;
    let action = object
        .get("action_semantic")?
        .as_str()?
        .replace(['\n', '\r'], " ");
    let pre = strings(&object, "preconditions")?;
    let eff = strings(&object, "effects")?;
    let mut out = String::from("* Prediction Rationale:\n");
    for r in &rationale {
        let _ = writeln!(out, "- {r}");
    }
    let _ = write!(
        out,
        "* Predicted Action:\nAction Semantic:\n- {}\nPrecondition:\n",
        action.trim()
    );
    bullet_lines(&mut out, &pre, "- ", "None");
    out.push_str("Effect:\n");
    bullet_lines(&mut out, &eff, "- ", "None");
    Some(out)
}

/// The refinement reply: rationale lines, then one SEARCH/REPLACE block whose SEARCH side
/// quotes consecutive actions of `procedure` exactly as the prompt printed them (at most
/// eight of them), and whose REPLACE side holds whole action blocks over
/// `symbols` (or nothing, to delete).
///
/// ```
/// use nesy_core::{Tier, Vocabulary};
/// use nesy_reasoner::constraints::{Symbols, patch_constraint};
/// let symbols = Symbols::new(&Vocabulary::new(), Tier::Full, ["red_cube"], []);
/// let grammar = patch_constraint(&symbols, &[]).grammar;
/// assert!(grammar.contains("<<<<<<< SEARCH"));
/// ```
pub fn patch_constraint(symbols: &Symbols, procedure: &[Operator]) -> ReplyConstraint {
    let mut grammar = format!(
        "root ::= \"* Refinement rationale:\\n\" reason{{1,{RATIONALE_LINES}}} \
         \"\\n* Refinement patch:\\n<<<<<<< SEARCH\\n\" search \"=======\\n\" replace \">>>>>>> REPLACE\\n\"\n\
         replace ::= \"\" | block (\"\\n\" block){{0,{}}}\n\
         block ::= name \"\\n- Preconditions:\\n\" (\"\\tNone\\n\" | (\"\\t\" literal \"\\n\"){{1,{LITERALS_PER_SECTION}}}) \
         \"- Effects:\\n\" (\"\\t\" literal \"\\n\"){{1,{LITERALS_PER_SECTION}}}\n\
         name ::= [A-Za-z] [A-Za-z0-9_]{{0,79}}\n",
        REPLACEMENT_ACTIONS - 1
    );
    grammar.push_str(&search_rules(procedure));
    grammar.push_str(&text_rules());
    grammar.push_str(&symbols.literal_rules());
    let (_, literal) = symbols.json_patterns();
    let mut names: Vec<String> = procedure.iter().map(Operator::display_name).collect();
    names.dedup();
    let search = if names.is_empty() {
        json!({"type": "array", "items": {"type": "string"}, "maxItems": 0})
    } else {
        array_schema(json!({"type": "string", "enum": names}), 1, SEARCH_SPAN)
    };
    let json_schema = object_schema(vec![
        ("rationale", array_schema(line_schema(), 1, RATIONALE_LINES)),
        ("search", search),
        (
            "replace",
            array_schema(block_schema(&literal), 0, REPLACEMENT_ACTIONS),
        ),
    ]);
    ReplyConstraint {
        name: "patch".into(),
        grammar,
        json_schema: Some(json_schema),
    }
}

/// A patch given as JSON under [`patch_constraint`]'s schema, written out in the prompt's
/// layout: the SEARCH side prints the first run of consecutive actions of `procedure` with
/// the names given (or the names alone when no run has them, which the loop then reports as
/// a SEARCH side it cannot find), the REPLACE side the blocks given. `None` when the reply
/// is not such an object.
pub fn patch_layout(reply: &str, procedure: &[Operator]) -> Option<String> {
    let object = json_object(reply)?;
    let rationale = strings(&object, "rationale")?;
    let search = strings(&object, "search")?;
    let mut out = String::from("* Refinement rationale:\n");
    for r in &rationale {
        let _ = writeln!(out, "- {r}");
    }
    out.push_str("\n* Refinement patch:\n<<<<<<< SEARCH\n");
    let names: Vec<String> = procedure.iter().map(Operator::display_name).collect();
    let start = (!search.is_empty())
        .then(|| names.windows(search.len()).position(|w| w == search.as_slice()))
        .flatten();
    match start {
        Some(start) => {
            let run: Vec<String> = procedure[start..start + search.len()]
                .iter()
                .map(|op| format!("{op}\n"))
                .collect();
            out.push_str(&run.join("\n"));
        }
        None => search.iter().for_each(|name| {
            let _ = writeln!(out, "{name}");
        }),
    }
    out.push_str("=======\n");
    let mut blocks = Vec::new();
    for block in object.get("replace")?.as_array()? {
        let block = block.as_object()?;
        let name = block.get("name")?.as_str()?.trim();
        let mut text = format!("{name}\n- Preconditions:\n");
        bullet_lines(&mut text, &strings(block, "preconditions")?, "\t", "\tNone");
        text.push_str("- Effects:\n");
        bullet_lines(&mut text, &strings(block, "effects")?, "\t", "\tNone");
        blocks.push(text);
    }
    out.push_str(&blocks.join("\n"));
    out.push_str(">>>>>>> REPLACE\n");
    Some(out)
}

/// `search` and one rule per action of `procedure` (`step0`, `step1`, ...): every run of
/// up to [`SEARCH_SPAN`] consecutive actions, blocks separated by a blank line as the
/// prompt prints a procedure. An empty procedure leaves the SEARCH side empty.
fn search_rules(procedure: &[Operator]) -> String {
    if procedure.is_empty() {
        return "search ::= \"\"\n".into();
    }
    let mut rules = String::new();
    let mut runs = Vec::new();
    for start in 0..procedure.len() {
        for end in start..procedure.len().min(start + SEARCH_SPAN) {
            let steps: Vec<String> = (start..=end).map(|i| format!("step{i}")).collect();
            runs.push(steps.join(" \"\\n\" "));
        }
    }
    let _ = writeln!(rules, "search ::= ({})", runs.join(") | ("));
    for (i, operator) in procedure.iter().enumerate() {
        let _ = writeln!(rules, "step{i} ::= {}", gbnf_literal(&format!("{operator}\n")));
    }
    rules
}

/// The state-translation reply: `None`, or one grounded atom per line over `symbols`.
///
/// ```
/// use nesy_core::{Tier, Vocabulary};
/// use nesy_reasoner::constraints::{Symbols, translation_constraint};
/// let symbols = Symbols::new(&Vocabulary::new(), Tier::Partial, ["red_cube"], []);
/// assert!(translation_constraint(&symbols).grammar.starts_with("root ::= \"None\\n\" | (\"- \" atom"));
/// ```
pub fn translation_constraint(symbols: &Symbols) -> ReplyConstraint {
    let mut grammar = format!("root ::= \"None\\n\" | (\"- \" atom \"\\n\"){{1,{ATOMS_PER_STATE}}}\n");
    grammar.push_str(&symbols.literal_rules());
    let (atom, _) = symbols.json_patterns();
    let json_schema = object_schema(vec![(
        "atoms",
        array_schema(pattern_schema(&atom), 0, ATOMS_PER_STATE),
    )]);
    ReplyConstraint {
        name: "translate".into(),
        grammar,
        json_schema: Some(json_schema),
    }
}

/// A translation given as JSON under [`translation_constraint`]'s schema, written out as
/// the prompt's list of atoms (`None` for an empty list); `None` when the reply is not such
/// an object.
///
/// ```
/// use nesy_reasoner::constraints::translation_layout;
/// assert_eq!(translation_layout(r#"{"atoms": ["(GripperOpen)"]}"#).unwrap(), "- (GripperOpen)\n");
/// assert_eq!(translation_layout(r#"{"atoms": []}"#).unwrap(), "None\n");
/// ```
pub fn translation_layout(reply: &str) -> Option<String> {
    let atoms = strings(&json_object(reply)?, "atoms")?;
    let mut out = String::new();
    if atoms.is_empty() {
        out.push_str("None\n");
    }
    for atom in &atoms {
        let _ = writeln!(out, "- {atom}");
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nesy_core::text::{
        normalize_reply, parse_induction_reply, parse_procedure, parse_refinement_reply, parse_state_list,
    };

    fn symbols() -> Symbols {
        Symbols {
            predicates: vec![
                ("GripperOpen".into(), 0),
                ("OnTopOf".into(), 2),
                ("Open".into(), 1),
            ],
            objects: vec!["red_cube".into(), "floor".into()],
        }
    }

    const LITERALS: &str = r#"pred0 ::= "GripperOpen"
pred1 ::= "Open"
pred2 ::= "OnTopOf"
obj ::= "red_cube" | "floor"
arg ::= obj | "?x"
atom ::= "(" (pred0 | pred1 " " obj | pred2 " " obj " " obj) ")"
qatom ::= "(" (pred0 | pred1 " " arg | pred2 " " arg " " arg) ")"
literal ::= atom | "(not " atom ")" | "(forall (?x - thing) " qliteral ")"
qliteral ::= qatom | "(not " qatom ")"
"#;

    #[test]
    fn induction_grammar_is_the_prompt_layout_over_the_symbols() {
        let expected = format!(
            r#"root ::= "* Prediction Rationale:\n" reason{{1,4}} "* Predicted Action:\nAction Semantic:\n- " line "\nPrecondition:\n" pre "Effect:\n" eff
pre ::= "None\n" | ("- " literal "\n"){{1,12}}
eff ::= ("- " literal "\n"){{1,12}}
reason ::= "- " line "\n"
line ::= [^\n]{{1,200}}
{LITERALS}"#
        );
        assert_eq!(induction_constraint(&symbols()).grammar, expected);
    }

    #[test]
    fn translation_grammar_lists_atoms_or_none() {
        let expected = format!("root ::= \"None\\n\" | (\"- \" atom \"\\n\"){{1,48}}\n{LITERALS}");
        assert_eq!(translation_constraint(&symbols()).grammar, expected);
    }

    #[test]
    fn patch_grammar_quotes_runs_of_the_procedure() {
        let procedure = parse_procedure(
            "OpenDrawer\n- Preconditions:\n\t(GripperOpen)\n- Effects:\n\t(Open floor)\n\n\
             PlaceCube\n- Preconditions:\n\tNone\n- Effects:\n\t(OnTopOf red_cube floor)",
        )
        .unwrap();
        let expected = format!(
            r#"root ::= "* Refinement rationale:\n" reason{{1,4}} "\n* Refinement patch:\n<<<<<<< SEARCH\n" search "=======\n" replace ">>>>>>> REPLACE\n"
replace ::= "" | block ("\n" block){{0,5}}
block ::= name "\n- Preconditions:\n" ("\tNone\n" | ("\t" literal "\n"){{1,12}}) "- Effects:\n" ("\t" literal "\n"){{1,12}}
name ::= [A-Za-z] [A-Za-z0-9_]{{0,79}}
search ::= (step0) | (step0 "\n" step1) | (step1)
step0 ::= "OpenDrawer\n- Preconditions:\n\t(GripperOpen)\n- Effects:\n\t(Open floor)\n"
step1 ::= "PlaceCube\n- Preconditions:\n\tNone\n- Effects:\n\t(OnTopOf red_cube floor)\n"
reason ::= "- " line "\n"
line ::= [^\n]{{1,200}}
{LITERALS}"#
        );
        assert_eq!(patch_constraint(&symbols(), &procedure).grammar, expected);
    }

    const ATOM: &str = r"\((?:(?:GripperOpen)|(?:Open) (?:red_cube|floor)|(?:OnTopOf) (?:red_cube|floor) (?:red_cube|floor))\)";
    const QATOM: &str = r"\((?:(?:GripperOpen)|(?:Open) (?:(?:red_cube|floor)|\?x)|(?:OnTopOf) (?:(?:red_cube|floor)|\?x) (?:(?:red_cube|floor)|\?x))\)";

    fn literal_pattern() -> String {
        format!(r"^(?:{ATOM}|\(not {ATOM}\)|\(forall \(\?x - thing\) (?:{QATOM}|\(not {QATOM}\))\))$")
    }

    #[test]
    fn induction_schema_is_the_action_block_over_the_symbols() {
        let literal = literal_pattern();
        let expected = json!({
            "type": "object",
            "properties": {
                "rationale": {"type": "array", "items": {"type": "string", "minLength": 1, "maxLength": 200}, "minItems": 1, "maxItems": 4},
                "action_semantic": {"type": "string", "minLength": 1, "maxLength": 200},
                "preconditions": {"type": "array", "items": {"type": "string", "pattern": literal}, "minItems": 0, "maxItems": 12},
                "effects": {"type": "array", "items": {"type": "string", "pattern": literal}, "minItems": 1, "maxItems": 12}
            },
            "required": ["rationale", "action_semantic", "preconditions", "effects"],
            "additionalProperties": false
        });
        assert_eq!(induction_constraint(&symbols()).json_schema, Some(expected));
    }

    #[test]
    fn translation_schema_lists_grounded_atoms() {
        let expected = json!({
            "type": "object",
            "properties": {
                "atoms": {"type": "array", "items": {"type": "string", "pattern": format!("^{ATOM}$")}, "minItems": 0, "maxItems": 48}
            },
            "required": ["atoms"],
            "additionalProperties": false
        });
        assert_eq!(translation_constraint(&symbols()).json_schema, Some(expected));
    }

    #[test]
    fn patch_schema_names_the_procedures_actions() {
        let procedure = parse_procedure(
            "OpenDrawer\n- Preconditions:\n\t(GripperOpen)\n- Effects:\n\t(Open floor)\n\n\
             PlaceCube\n- Preconditions:\n\tNone\n- Effects:\n\t(OnTopOf red_cube floor)",
        )
        .unwrap();
        let literal = literal_pattern();
        let expected = json!({
            "type": "object",
            "properties": {
                "rationale": {"type": "array", "items": {"type": "string", "minLength": 1, "maxLength": 200}, "minItems": 1, "maxItems": 4},
                "search": {"type": "array", "items": {"type": "string", "enum": ["OpenDrawer", "PlaceCube"]}, "minItems": 1, "maxItems": 8},
                "replace": {"type": "array", "items": {
                    "type": "object",
                    "properties": {
                        "name": {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]{0,79}$"},
                        "preconditions": {"type": "array", "items": {"type": "string", "pattern": literal}, "minItems": 0, "maxItems": 12},
                        "effects": {"type": "array", "items": {"type": "string", "pattern": literal}, "minItems": 1, "maxItems": 12}
                    },
                    "required": ["name", "preconditions", "effects"],
                    "additionalProperties": false
                }, "minItems": 0, "maxItems": 6}
            },
            "required": ["rationale", "search", "replace"],
            "additionalProperties": false
        });
        assert_eq!(
            patch_constraint(&symbols(), &procedure).json_schema,
            Some(expected)
        );
        // With no procedure yet, nothing can be searched for.
        let empty = patch_constraint(&symbols(), &[]).json_schema.unwrap();
        assert_eq!(empty["properties"]["search"]["maxItems"], 0);
    }

    /// JSON replies the schemas allow, written out in the layout, are read by the same
    /// parsers as the grammar's replies.
    #[test]
    fn json_replies_the_schemas_allow_parse_after_layout() {
        let induction = induction_layout(
            r#"{"rationale": ["The cube was put down."], "action_semantic": "place the cube",
                "preconditions": ["(not (OnTopOf red_cube floor))", "(forall (?x - thing) (not (Open ?x)))"],
                "effects": ["(OnTopOf red_cube floor)"]}"#,
        )
        .unwrap();
        let parsed = parse_induction_reply(&normalize_reply(&induction)).unwrap();
        assert_eq!(parsed.operator.pre.len(), 2);
        assert_eq!(parsed.operator.eff.len(), 1);

        let procedure = parse_procedure(
            "OpenDrawer\n- Preconditions:\n\t(GripperOpen)\n- Effects:\n\t(Open floor)\n\n\
             PlaceCube\n- Preconditions:\n\tNone\n- Effects:\n\t(OnTopOf red_cube floor)",
        )
        .unwrap();
        let patch = patch_layout(
            r#"{"rationale": ["Drop the opening."], "search": ["OpenDrawer", "PlaceCube"],
                "replace": [{"name": "PlaceCube", "preconditions": [], "effects": ["(OnTopOf red_cube floor)"]}]}"#,
            &procedure,
        )
        .unwrap();
        let parsed = parse_refinement_reply(&normalize_reply(&patch)).unwrap();
        assert_eq!(parsed.patches[0].search, procedure);
        assert_eq!(parsed.patches[0].replace, procedure[1..]);
        // Names that are no run of the procedure are written out as they are, for the loop
        // to report.
        let unknown = patch_layout(
            r#"{"rationale": ["x"], "search": ["PlaceCube", "OpenDrawer"], "replace": []}"#,
            &procedure,
        )
        .unwrap();
        assert!(
            unknown.contains("<<<<<<< SEARCH\nPlaceCube\nOpenDrawer\n=======\n>>>>>>> REPLACE\n"),
            "{unknown}"
        );

        let state =
            translation_layout(r#"{"atoms": ["(GripperOpen)", "(OnTopOf red_cube floor)"]}"#).unwrap();
        assert_eq!(parse_state_list(&normalize_reply(&state)).unwrap().len(), 2);
        assert!(translation_layout(r#"{"atoms": "(GripperOpen)"}"#).is_none());
    }

    /// Replies written the way each grammar allows are read by the parsers the loop uses.
    #[test]
    fn replies_the_grammars_allow_parse() {
        let induction = "* Prediction Rationale:\n- The cube was put down.\n* Predicted Action:\nAction Semantic:\n- place the cube\nPrecondition:\n- (not (OnTopOf red_cube floor))\n- (forall (?x - thing) (not (Open ?x)))\nEffect:\n- (OnTopOf red_cube floor)\n";
        let parsed = parse_induction_reply(&normalize_reply(induction)).unwrap();
        assert_eq!(parsed.operator.pre.len(), 2);

        let procedure = parse_procedure(
            "OpenDrawer\n- Preconditions:\n\t(GripperOpen)\n- Effects:\n\t(Open floor)\n\n\
             PlaceCube\n- Preconditions:\n\tNone\n- Effects:\n\t(OnTopOf red_cube floor)",
        )
        .unwrap();
        let patch = format!(
            "* Refinement rationale:\n- Drop the opening.\n\n* Refinement patch:\n<<<<<<< SEARCH\n{}\n\n{}\n=======\n{}\n>>>>>>> REPLACE\n",
            procedure[0], procedure[1], procedure[1]
        );
        let parsed = parse_refinement_reply(&normalize_reply(&patch)).unwrap();
        assert_eq!(parsed.patches[0].search, procedure);
        assert_eq!(parsed.patches[0].replace, procedure[1..]);

        let state =
            parse_state_list(&normalize_reply("- (GripperOpen)\n- (OnTopOf red_cube floor)\n")).unwrap();
        assert_eq!(state.len(), 2);
        assert!(parse_state_list(&normalize_reply("None\n")).unwrap().is_empty());
    }

    #[test]
    fn symbols_take_objects_from_the_states_once() {
        let state = parse_state_list("- (OnTopOf red_cube table)").unwrap();
        let symbols = Symbols::new(&Vocabulary::new(), Tier::Full, ["red_cube"], [&state]);
        assert_eq!(symbols.objects, ["red_cube", "table"]);
        assert!(
            symbols
                .predicates
                .iter()
                .any(|(name, arity)| name == "OnTopOf" && *arity == 2)
        );
    }
}
