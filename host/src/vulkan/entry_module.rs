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
use rspirv::dr::{Function, Instruction, Module, Operand};
use rspirv::spirv::Op;
use std::collections::{HashMap, HashSet};

/// A SPIR-V module parsed once, from which each entry point's module is cut
/// ([`EntryPoints::module_of`]): a pipeline's stages share one parse (parsing the kernel's
/// module is most of a cut's time).
pub struct EntryPoints {
    module: Module,
    /// Each function's index in `module.functions`, by its result id.
    function_index: HashMap<u32, usize>,
}

impl EntryPoints {
    /// Parses `words`; an error if they are not a SPIR-V module.
    pub fn parse(words: &[u32]) -> Result<EntryPoints, String> {
        let module =
            rspirv::dr::load_words(words).map_err(|e| format!("not a SPIR-V module: {e}"))?;
        let function_index = module
            .functions
            .iter()
            .enumerate()
            .filter_map(|(i, f)| function_id(f).map(|id| (id, i)))
            .collect();
        Ok(EntryPoints {
            module,
            function_index,
        })
    }

    /// The module with only the entry point named `entry` (see the module's documentation),
    /// as words. An error if no entry point has that name.
    pub fn module_of(&self, entry: &str) -> Result<Vec<u32>, String> {
        let m = &self.module;
        let named = |i: &&Instruction| matches!(i.operands.get(2), Some(Operand::LiteralString(s)) if s == entry);
        let entry_point = m
            .entry_points
            .iter()
            .find(named)
            .ok_or_else(|| format!("the module has no entry point {entry:?}"))?;
        let function = entry_point
            .operands
            .get(1)
            .and_then(id_ref)
            .ok_or_else(|| format!("entry point {entry:?} names no function"))?;

        // The functions `function` reaches, by their calls.
        let mut kept = vec![false; m.functions.len()];
        let mut frontier = vec![function];
        while let Some(caller) = frontier.pop() {
            let Some(&index) = self.function_index.get(&caller) else {
                return Err(format!("entry point {entry:?} calls an undefined function"));
            };
            if std::mem::replace(&mut kept[index], true) {
                continue;
            }
            let f = &m.functions[index];
            for i in f.blocks.iter().flat_map(|b| &b.instructions) {
                if i.class.opcode == Op::FunctionCall {
                    frontier.extend(i.operands.first().and_then(id_ref));
                }
            }
        }
        // Everything the removed functions defined, whose names and decorations go with them.
        let removed: HashSet<u32> = m
            .functions
            .iter()
            .zip(&kept)
            .filter(|(_, &k)| !k)
            .flat_map(|(f, _)| f.all_inst_iter().filter_map(|i| i.result_id))
            .collect();
        let targets_kept = |i: &&Instruction| {
            i.operands
                .first()
                .and_then(id_ref)
                .is_none_or(|t| !removed.contains(&t))
        };
        let modes_of_entry =
            |i: &&Instruction| i.operands.first().and_then(id_ref) == Some(function);

        // Assembled section by section, in the module's order (`Module::all_inst_iter`).
        let mut words = m.header.as_ref().map(|h| h.assemble()).unwrap_or_default();
        let instructions = m
            .capabilities
            .iter()
            .chain(&m.extensions)
            .chain(&m.ext_inst_imports)
            .chain(&m.memory_model)
            .chain([entry_point])
            .chain(m.execution_modes.iter().filter(modes_of_entry))
            .chain(&m.debug_string_source)
            .chain(m.debug_names.iter().filter(targets_kept))
            .chain(&m.debug_module_processed)
            .chain(m.annotations.iter().filter(targets_kept))
            .chain(&m.types_global_values);
        for i in instructions {
            words.extend(i.assemble());
        }
        for (f, _) in m.functions.iter().zip(&kept).filter(|(_, &k)| k) {
            words.extend(f.assemble());
        }
        Ok(words)
    }
}

fn function_id(f: &Function) -> Option<u32> {
    f.def.as_ref().and_then(|d| d.result_id)
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
        let entry_points = EntryPoints::parse(&words).unwrap();
        assert!(whole.entry_points.len() > 1);
        for e in &whole.entry_points {
            let Some(Operand::LiteralString(name)) = e.operands.get(2) else {
                panic!("an entry point without a name")
            };
            let cut = rspirv::dr::load_words(entry_points.module_of(name).unwrap()).unwrap();
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
        assert!(entry_points.module_of("shaders::no_such_stage").is_err());
    }
}
