//! The template compiler's schema table against `assets/pddl/nesy-world.pddl`, and every
//! schema compiled on both end effectors.

use nesy_core::Embodiment;
use nesy_core::Operator;
use nesy_sim::codegen::{compile_policy, resolve_action};
use nesy_sim::domain::schema_names;

const DOMAIN: &str = include_str!("../../../../assets/pddl/nesy-world.pddl");

fn camel(s: &str) -> String {
    s.split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(|w| w[..1].to_uppercase() + &w[1..])
        .collect()
}

#[test]
fn the_table_lists_exactly_the_domain_schemas() {
    let domain = nesy_core::pddl::parse_domain(DOMAIN).expect("the domain parses");
    let in_file: Vec<String> = domain.actions.iter().map(|a| a.name.clone()).collect();
    let in_table: Vec<String> = schema_names().map(str::to_owned).collect();
    assert_eq!(in_file, in_table);
}

#[test]
fn every_schema_compiles_on_both_end_effectors() {
    let domain = nesy_core::pddl::parse_domain(DOMAIN).unwrap();
    let objects: Vec<String> = [
        "floor",
        "board",
        "toy_box",
        "left_chess_box",
        "red_cube",
        "hinge_body",
        "hinge_lid",
        "hinge_handle",
        "drawer_body",
        "bottom_drawer",
        "top_drawer",
        "bottom_drawer_handle",
        "top_drawer_handle",
        "magnetic_hook",
        "black_screws",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for schema in &domain.actions {
        let args: Vec<&str> = schema
            .params
            .iter()
            .map(|p| match p.ty.as_str() {
                "item" => "red_cube",
                "surface" => "floor",
                "box" => "toy_box",
                "tool" => "magnetic_hook",
                "pieces" => "black_screws",
                other => panic!("unexpected parameter type {other}"),
            })
            .collect();
        let name = camel(&format!("{} {}", schema.name, args.join(" ")));
        let resolved = resolve_action(&name, &objects).unwrap_or_else(|| panic!("{name} does not resolve"));
        assert_eq!(resolved.schema, schema.name);
        assert_eq!(resolved.args, args);
        for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
            let policy = compile_policy(
                &[Operator::new(name.clone(), vec![], vec![])],
                &objects,
                embodiment,
                false,
            )
            .unwrap();
            let wrong = if embodiment == Embodiment::Vacuum {
                [
                    "close_gripper(",
                    "open_gripper(",
                    "grasp_handle(",
                    "release_handle(",
                ]
            } else {
                [
                    "activate_vacuum(",
                    "deactivate_vacuum(",
                    "attach_vacuum_handle(",
                    "detach_vacuum_handle(",
                ]
            };
            assert!(
                wrong.iter().all(|w| !policy.code.contains(w)),
                "{name} on {embodiment}:\n{}",
                policy.code
            );
        }
    }
}
