//! One stage's module: the kernel's SPIR-V module cut down to one entry point and the functions
//! it calls, so that each stage of a pipeline is given only its own code.
//!
//! rust-gpu writes every entry point of the kernel into one module, and a driver, like the
//! validation layers, reads a stage's whole module for each stage that names it: the
//! ray-generation function is 93% of the kernel's module, so every closest-hit, any-hit,
//! intersection and miss stage paid for reading it again (measured in `docs/performance.md`,
//! "Pipeline creation"). Cut per stage, the ray-generation stage reads it once.
//!
//! What is removed: the other entry points, their execution modes, every function the kept entry
//! point does not reach through `OpFunctionCall`, and the names and decorations of what those
//! functions defined. Types, constants and global variables stay (the kept function's interface
//! is a subset of them; an unused declaration is valid SPIR-V). The invariant: every kept
//! instruction is the same instruction, in the same order, so a stage computes what it computed
//! in the whole module.

use rspirv::binary::Assemble;
use rspirv::dr::{Instruction, Operand};
use rspirv::spirv::Op;
use std::collections::HashSet;

/// `words` (a SPIR-V module) with only the entry point named `entry` (see the module's
/// documentation). An error if the words do not parse or no entry point has that name.
pub fn entry_point_module(words: &[u32], entry: &str) -> Result<Vec<u32>, String> {
    let mut module =
        rspirv::dr::load_words(words).map_err(|e| format!("not a SPIR-V module: {e}"))?;
    let named = |i: &Instruction| matches!(i.operands.get(2), Some(Operand::LiteralString(s)) if s == entry);
    let function = module
        .entry_points
        .iter()
        .find(|i| named(i))
        .and_then(|i| i.operands.get(1).and_then(id_ref))
        .ok_or_else(|| format!("the module has no entry point {entry:?}"))?;
    module.entry_points.retain(named);
    module
        .execution_modes
        .retain(|i| i.operands.first().and_then(id_ref) == Some(function));

    // The functions `function` reaches, by their calls.
    let id_of = |f: &rspirv::dr::Function| f.def.as_ref().and_then(|d| d.result_id);
    let mut kept = HashSet::from([function]);
    let mut frontier = vec![function];
    while let Some(caller) = frontier.pop() {
        let Some(f) = module.functions.iter().find(|f| id_of(f) == Some(caller)) else {
            return Err(format!("entry point {entry:?} calls an undefined function"));
        };
        for i in f.blocks.iter().flat_map(|b| &b.instructions) {
            if i.class.opcode == Op::FunctionCall {
                if let Some(callee) = i.operands.first().and_then(id_ref) {
                    if kept.insert(callee) {
                        frontier.push(callee);
                    }
                }
            }
        }
    }
    // Everything the removed functions defined, whose names and decorations go with them.
    let mut removed = HashSet::new();
    for f in module
        .functions
        .iter()
        .filter(|f| !kept.contains(&id_of(f).unwrap_or(0)))
    {
        let blocks = f.blocks.iter();
        let instructions = f
            .def
            .iter()
            .chain(&f.parameters)
            .chain(blocks.flat_map(|b| b.label.iter().chain(&b.instructions)));
        removed.extend(instructions.filter_map(|i| i.result_id));
    }
    module
        .functions
        .retain(|f| kept.contains(&id_of(f).unwrap_or(0)));
    let targets_kept = |i: &Instruction| {
        i.operands
            .first()
            .and_then(id_ref)
            .is_none_or(|t| !removed.contains(&t))
    };
    module.debug_names.retain(targets_kept);
    module.annotations.retain(targets_kept);
    Ok(module.assemble())
}

fn id_ref(o: &Operand) -> Option<u32> {
    match o {
        Operand::IdRef(id) => Some(*id),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kernel's module: each entry point's cut keeps that entry point alone, and its
    /// function's instructions word for word.
    #[test]
    fn each_cut_keeps_its_entry_point_and_its_function_word_for_word() {
        let words = ash::util::read_spv(&mut std::io::Cursor::new(crate::KERNEL_SPV)).unwrap();
        let whole = rspirv::dr::load_words(&words).unwrap();
        assert!(whole.entry_points.len() > 1);
        for e in &whole.entry_points {
            let Some(Operand::LiteralString(name)) = e.operands.get(2) else {
                panic!("an entry point without a name")
            };
            let cut = rspirv::dr::load_words(entry_point_module(&words, name).unwrap()).unwrap();
            assert_eq!(cut.entry_points.len(), 1);
            assert_eq!(cut.entry_points[0].assemble(), e.assemble(), "{name}");
            assert_eq!(cut.functions.len(), 1, "{name}");
            let f = id_ref(&e.operands[1]).unwrap();
            let original = whole
                .functions
                .iter()
                .find(|g| g.def.as_ref().unwrap().result_id == Some(f))
                .unwrap();
            assert_eq!(cut.functions[0].assemble(), original.assemble(), "{name}");
            assert_eq!(
                cut.types_global_values.len(),
                whole.types_global_values.len()
            );
            assert!(cut
                .execution_modes
                .iter()
                .all(|m| id_ref(&m.operands[0]) == Some(f)));
        }
        assert!(entry_point_module(&words, "shaders::no_such_stage").is_err());
    }
}
