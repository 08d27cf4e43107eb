//! The grammar each reply must follow, built from what the call already knows: the
//! predicates of the prompt's tier with their arities, the objects of the scene, and (for a
//! patch) the actions of the current procedure. Sent to servers that can hold generation to
//! a grammar ([`nesy_vlm::ReplyConstraint`]), it keeps even a weak model inside the layout
//! the parsers read; the parsers, the verifier and the re-ask budgets stay as they are.
//!
//! Every grammar bounds its free text (rationale lines, action names) and its lists, so a
//! constrained reply cannot run away.

use std::fmt::Write as _;

use nesy_core::adapt::TaskContext;
use nesy_core::{Operator, State, Tier, Vocabulary};
use nesy_vlm::{ReplyConstraint, gbnf_literal};

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
    ReplyConstraint {
        name: "induce".into(),
        grammar,
        json_schema: None,
    }
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
    ReplyConstraint {
        name: "patch".into(),
        grammar,
        json_schema: None,
    }
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
    ReplyConstraint {
        name: "translate".into(),
        grammar,
        json_schema: None,
    }
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
