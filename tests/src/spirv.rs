//! A small reader of SPIR-V modules for tests: entry points, and the layout (member offsets,
//! array stride) of the structs behind storage-buffer bindings.

use std::collections::{BTreeSet, HashMap};

const OP_CAPABILITY: u32 = 17;
const OP_EXTENSION: u32 = 10;
const OP_ENTRY_POINT: u32 = 15;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;
const DECORATION_ARRAY_STRIDE: u32 = 6;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const DECORATION_OFFSET: u32 = 35;
const DECORATION_SPEC_ID: u32 = 1;

/// The parts of a module the tests look at.
#[derive(Default, Debug)]
pub struct Module {
    pub entry_points: BTreeSet<(u32, String)>,
    /// The module's OpCapability operands (SPIR-V capability numbers).
    pub capabilities: BTreeSet<u32>,
    /// The module's OpExtension names.
    pub extensions: BTreeSet<String>,
    /// SpecId decorations: the module's specialization-constant ids.
    pub spec_ids: BTreeSet<u32>,
    structs: HashMap<u32, Vec<u32>>,
    runtime_arrays: HashMap<u32, u32>,
    arrays: HashMap<u32, u32>,
    pointers: HashMap<u32, u32>,
    variables: HashMap<u32, u32>,
    bindings: HashMap<(u32, u32), u32>,
    offsets: HashMap<(u32, u32), u32>,
    strides: HashMap<u32, u32>,
}

/// Layout of the struct behind a binding: its members' offsets and, for runtime arrays of
/// it, the array stride.
#[derive(Debug, PartialEq, Eq)]
pub struct StructLayout {
    pub offsets: Vec<u32>,
    pub stride: Option<u32>,
}

impl Module {
    pub fn parse(spv: &[u8]) -> Module {
        assert_eq!(spv.len() % 4, 0);
        let words: Vec<u32> = spv
            .as_chunks::<4>()
            .0
            .iter()
            .map(|c| u32::from_le_bytes(*c))
            .collect();
        assert_eq!(words[0], 0x0723_0203, "not a SPIR-V module");
        let mut m = Module::default();
        let mut i = 5;
        while i < words.len() {
            let count = (words[i] >> 16) as usize;
            let op = words[i] & 0xffff;
            assert!(
                count > 0 && i + count <= words.len(),
                "malformed instruction at {i}"
            );
            let w = &words[i..i + count];
            match op {
                OP_ENTRY_POINT => {
                    let bytes: Vec<u8> = w[3..].iter().flat_map(|x| x.to_le_bytes()).collect();
                    let end = bytes.iter().position(|&b| b == 0).unwrap();
                    m.entry_points
                        .insert((w[1], String::from_utf8(bytes[..end].to_vec()).unwrap()));
                }
                OP_CAPABILITY => {
                    m.capabilities.insert(w[1]);
                }
                OP_EXTENSION => {
                    let bytes: Vec<u8> = w[1..].iter().flat_map(|x| x.to_le_bytes()).collect();
                    let end = bytes.iter().position(|&b| b == 0).unwrap();
                    m.extensions
                        .insert(String::from_utf8(bytes[..end].to_vec()).unwrap());
                }
                OP_TYPE_STRUCT => {
                    m.structs.insert(w[1], w[2..].to_vec());
                }
                OP_TYPE_RUNTIME_ARRAY => {
                    m.runtime_arrays.insert(w[1], w[2]);
                }
                OP_TYPE_ARRAY => {
                    m.arrays.insert(w[1], w[2]);
                }
                OP_TYPE_POINTER => {
                    m.pointers.insert(w[1], w[3]);
                }
                OP_VARIABLE => {
                    m.variables.insert(w[2], w[1]);
                }
                OP_DECORATE if count >= 4 => match w[2] {
                    DECORATION_BINDING => {
                        m.bindings.entry((w[1], 1)).or_insert(w[3]);
                    }
                    DECORATION_DESCRIPTOR_SET => {
                        m.bindings.entry((w[1], 0)).or_insert(w[3]);
                    }
                    DECORATION_ARRAY_STRIDE => {
                        m.strides.insert(w[1], w[3]);
                    }
                    DECORATION_SPEC_ID => {
                        m.spec_ids.insert(w[3]);
                    }
                    _ => {}
                },
                OP_MEMBER_DECORATE if count >= 5 && w[3] == DECORATION_OFFSET => {
                    m.offsets.insert((w[1], w[2]), w[4]);
                }
                _ => {}
            }
            i += count;
        }
        m
    }

    fn layout_of(&self, st: u32, stride: Option<u32>) -> StructLayout {
        let members = &self.structs[&st];
        StructLayout {
            offsets: (0..members.len() as u32)
                .map(|k| self.offsets[&(st, k)])
                .collect(),
            stride,
        }
    }

    /// The layout of the struct that is member `member` of the struct behind the storage
    /// buffer at (set, binding) (a part of `RenderParams`, say).
    pub fn member_layout(&self, set: u32, binding: u32, member: u32) -> StructLayout {
        let outer = self.binding_struct(set, binding);
        let inner = self.structs[&outer][member as usize];
        assert!(
            self.structs.contains_key(&inner),
            "member {member} of the struct at binding {binding} is not a struct"
        );
        self.layout_of(inner, None)
    }

    /// The type behind the storage buffer at (set, binding): a struct, or a runtime array.
    fn binding_struct(&self, set: u32, binding: u32) -> u32 {
        let var = self
            .variables
            .keys()
            .find(|v| {
                self.bindings.get(&(**v, 0)) == Some(&set)
                    && self.bindings.get(&(**v, 1)) == Some(&binding)
            })
            .unwrap_or_else(|| panic!("no variable at set {set} binding {binding}"));
        let block = self.pointers[&self.variables[var]];
        let members = &self.structs[&block];
        assert_eq!(members.len(), 1, "buffer block with one member");
        members[0]
    }

    /// The layout of the data behind the storage buffer at (set, binding): the block's only
    /// member, or the element of the runtime array it holds.
    pub fn binding_layout(&self, set: u32, binding: u32) -> StructLayout {
        let inner = self.binding_struct(set, binding);
        if let Some(&elem) = self.runtime_arrays.get(&inner) {
            self.layout_of(elem, self.strides.get(&inner).copied())
        } else {
            self.layout_of(inner, None)
        }
    }
}
