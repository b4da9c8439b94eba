//! A model's own expressions, compiled at run time to machine code without a C compiler.
//!
//! The Python layer lowers SymPy expressions (common subexpressions already shared) to an
//! [`Program`]: a flat postfix program over the inputs, with numbered temporaries. This module
//! holds no physics: it evaluates whatever expressions a model brings (a carrier's `ω_e(t)`,
//! `ε_e(t)`, `a_O(t)`).
//!
//! * [`Function::compile`] turns a program into machine code with a [`Compiler`]: the
//!   `poinsot-jit` crate's, over the `symjit` crate (AMD64, ARM64 or RISC-V; a few hundred
//!   microseconds), a crate of its own so that this one compiles without waiting for it. It
//!   falls back to interpreting the program where machine code cannot be had (a platform
//!   that forbids writable-executable memory, or the [`Interpreter`] as compiler).
//! * [`Program::eval`] interprets the program: the fallback, and the independent route the
//!   tests hold the machine code against.

use std::sync::Mutex;

/// The entry point of a program's machine code: `(memory, _, _, params)` (symjit's
/// `CompiledFunc<f64>`).
pub type CompiledFunc = fn(*const f64, *const &mut [f64], usize, *const f64) -> i32;

/// Push a constant (`value`).
pub const CONST: i64 = 0;
/// Push input number `value`.
pub const INPUT: i64 = 1;
/// Push temporary number `value`.
pub const LOAD: i64 = 2;
/// Pop into temporary number `value`.
pub const STORE: i64 = 3;
/// Pop into the next output.
pub const OUTPUT: i64 = 4;
/// Pop b, a; push a + b.
pub const ADD: i64 = 5;
/// Pop b, a; push a · b.
pub const MUL: i64 = 6;
/// Pop b, a; push a ^ b.
pub const POW: i64 = 7;
/// Unary functions: `UNARY + k` applies [`UNARY_NAMES`]`[k]`.
pub const UNARY: i64 = 100;
/// Binary functions: `BINARY + k` applies [`BINARY_NAMES`]`[k]` (pop b, a; push f(a, b)).
pub const BINARY: i64 = 200;

/// The unary functions a program may call, by their SymPy names.
pub const UNARY_NAMES: [&str; 17] = [
    "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh",
    "exp", "log", "sqrt", "Abs", "sign",
];
/// The binary functions a program may call, by their SymPy names.
pub const BINARY_NAMES: [&str; 3] = ["atan2", "Min", "Max"];

fn unary(k: usize, x: f64) -> f64 {
    match k {
        0 => x.sin(),
        1 => x.cos(),
        2 => x.tan(),
        3 => x.asin(),
        4 => x.acos(),
        5 => x.atan(),
        6 => x.sinh(),
        7 => x.cosh(),
        8 => x.tanh(),
        9 => x.asinh(),
        10 => x.acosh(),
        11 => x.atanh(),
        12 => x.exp(),
        13 => x.ln(),
        14 => x.sqrt(),
        15 => x.abs(),
        _ => {
            if x.is_nan() {
                x
            } else if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                0.0
            }
        }
    }
}

fn binary(k: usize, a: f64, b: f64) -> f64 {
    match k {
        0 => a.atan2(b),
        1 => {
            if a <= b {
                a
            } else {
                b
            }
        }
        _ => {
            if a >= b {
                a
            } else {
                b
            }
        }
    }
}

/// Instruction `i` of a [`Program`] (code `c`, value `v`) decoded and checked: a known code,
/// an input index below `n_inputs`, a temporary loaded only once stored (`stored`, which a
/// store extends). Returns the instruction and how many values it pops and pushes.
fn decode(
    i: usize,
    c: i64,
    v: f64,
    n_inputs: usize,
    stored: &mut Vec<bool>,
) -> Result<(Op, usize, usize), String> {
    Ok(match c {
        CONST => (Op::Const(v), 0, 1),
        INPUT => {
            let k = index(i, v)?;
            if k >= n_inputs {
                return Err(format!("instruction {i}: input {k} of {n_inputs}"));
            }
            (Op::Input(k), 0, 1)
        }
        LOAD => {
            let k = index(i, v)?;
            if !stored.get(k).copied().unwrap_or(false) {
                return Err(format!("instruction {i}: temporary {k} loaded before set"));
            }
            (Op::Load(k), 0, 1)
        }
        STORE => {
            let k = index(i, v)?;
            if k >= stored.len() {
                stored.resize(k + 1, false);
            }
            stored[k] = true;
            (Op::Store(k), 1, 0)
        }
        OUTPUT => (Op::Output, 1, 0),
        ADD => (Op::Add, 2, 1),
        MUL => (Op::Mul, 2, 1),
        POW => (Op::Pow, 2, 1),
        c if (UNARY..UNARY + UNARY_NAMES.len() as i64).contains(&c) => {
            (Op::Unary((c - UNARY) as usize), 1, 1)
        }
        c if (BINARY..BINARY + BINARY_NAMES.len() as i64).contains(&c) => {
            (Op::Binary((c - BINARY) as usize), 2, 1)
        }
        _ => return Err(format!("instruction {i}: unknown code {c}")),
    })
}

/// The value `v` of instruction `i` as an index: a whole number from 0 below 10⁹.
fn index(i: usize, v: f64) -> Result<usize, String> {
    if v >= 0.0 && v.fract() == 0.0 && v < 1e9 {
        Ok(v as usize)
    } else {
        Err(format!("instruction {i}: {v} is no index"))
    }
}

/// One instruction of a checked [`Program`] (indices in range, the stack never empty).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    Const(f64),
    Input(usize),
    Load(usize),
    Store(usize),
    Output,
    Add,
    Mul,
    Pow,
    Unary(usize),
    Binary(usize),
}

/// A checked postfix program: `n_inputs` inputs, `n_outputs` outputs.
#[derive(Clone, Debug)]
pub struct Program {
    ops: Vec<Op>,
    n_temps: usize,
    pub n_inputs: usize,
    pub n_outputs: usize,
}

impl Program {
    /// Its instructions, in order.
    pub fn ops(&self) -> &[Op] {
        &self.ops
    }

    /// The number of temporaries it stores and loads.
    pub fn n_temps(&self) -> usize {
        self.n_temps
    }

    /// The program of `codes` and `values` (one number per instruction: the constant, the
    /// input's or temporary's index, or ignored), checked: known codes, indices in range, no
    /// stack underflow, temporaries stored before they are loaded, an empty stack at the end,
    /// and exactly `n_outputs` outputs.
    pub fn new(
        codes: &[i64],
        values: &[f64],
        n_inputs: usize,
        n_outputs: usize,
    ) -> Result<Self, String> {
        if codes.len() != values.len() {
            return Err(format!(
                "the program's codes ({}) and values ({}) differ in length",
                codes.len(),
                values.len()
            ));
        }
        let mut ops = Vec::with_capacity(codes.len());
        let mut depth: usize = 0;
        let mut stored: Vec<bool> = Vec::new();
        let mut outputs = 0;
        for (i, (&c, &v)) in codes.iter().zip(values).enumerate() {
            let (op, pops, pushes) = decode(i, c, v, n_inputs, &mut stored)?;
            if matches!(op, Op::Output) {
                outputs += 1;
            }
            if depth < pops {
                return Err(format!("instruction {i}: the stack is empty"));
            }
            depth = depth - pops + pushes;
            ops.push(op);
        }
        if depth != 0 {
            return Err(format!("{depth} values are left on the stack"));
        }
        if outputs != n_outputs {
            return Err(format!("{outputs} outputs, expected {n_outputs}"));
        }
        Ok(Program {
            ops,
            n_temps: stored.len(),
            n_inputs,
            n_outputs,
        })
    }

    /// Interpret the program at `inputs`, writing `out` (`n_outputs`).
    pub fn eval(&self, inputs: &[f64], out: &mut [f64]) {
        let mut stack: Vec<f64> = Vec::with_capacity(16);
        let mut temps = vec![0.0; self.n_temps];
        let mut k = 0;
        for op in &self.ops {
            match *op {
                Op::Const(c) => stack.push(c),
                Op::Input(i) => stack.push(inputs[i]),
                Op::Load(i) => stack.push(temps[i]),
                Op::Store(i) => temps[i] = stack.pop().unwrap_or(f64::NAN),
                Op::Output => {
                    out[k] = stack.pop().unwrap_or(f64::NAN);
                    k += 1;
                }
                Op::Unary(f) => {
                    let x = stack.pop().unwrap_or(f64::NAN);
                    stack.push(unary(f, x));
                }
                Op::Add | Op::Mul | Op::Pow | Op::Binary(_) => {
                    let b = stack.pop().unwrap_or(f64::NAN);
                    let a = stack.pop().unwrap_or(f64::NAN);
                    stack.push(match *op {
                        Op::Add => a + b,
                        Op::Mul => a * b,
                        Op::Pow => power(a, b),
                        Op::Binary(f) => binary(f, a, b),
                        _ => unreachable!(),
                    });
                }
            }
        }
    }
}

/// `a ^ b`, with integer powers by repeated multiplication as symjit compiles them.
fn power(a: f64, b: f64) -> f64 {
    if b.fract() == 0.0 && b.abs() <= 64.0 {
        a.powi(b as i32)
    } else {
        a.powf(b)
    }
}

/// Machine code of a program: its memory holds the inputs at `first_input` and the outputs
/// at `first_output`. The code reads and writes only the memory it is given, so every thread
/// (every [`Scratch`]) runs it on a copy of its own.
pub struct MachineCode {
    /// Owns the executable memory that `func` points into.
    _owner: Box<dyn Send + Sync>,
    func: CompiledFunc,
    params: Vec<f64>,
    /// The memory as compiled (constants in place): each scratch starts as a copy.
    template: Vec<f64>,
    first_input: usize,
    first_output: usize,
}

impl MachineCode {
    /// The machine code of `program` at `func` (kept alive by `owner`), with its parameters and
    /// its memory as compiled; `None` when the program's inputs (at `first_input`) or outputs
    /// (at `first_output`) do not fit in that memory.
    ///
    /// # Safety
    /// `func` must read `params` and read and write `memory` (a copy of `template`) only, and
    /// take its inputs and leave its outputs where said, for as long as `owner` lives.
    pub unsafe fn new(
        program: &Program,
        owner: Box<dyn Send + Sync>,
        func: CompiledFunc,
        params: Vec<f64>,
        template: Vec<f64>,
        first_input: usize,
        first_output: usize,
    ) -> Option<Self> {
        if first_input + program.n_inputs > template.len()
            || first_output + program.n_outputs > template.len()
        {
            return None;
        }
        Some(MachineCode {
            _owner: owner,
            func,
            params,
            template,
            first_input,
            first_output,
        })
    }
}

/// Turns a [`Program`] into [`MachineCode`], or declines (then the program is interpreted).
pub trait Compiler {
    fn machine_code(&self, program: &Program) -> Option<MachineCode>;
}

/// The compiler that declines: programs are interpreted ([`Program::eval`]).
pub struct Interpreter;

impl Compiler for Interpreter {
    fn machine_code(&self, _program: &Program) -> Option<MachineCode> {
        None
    }
}

/// The working memory of one evaluator of a [`Function`] (a thread, a member of an ensemble):
/// evaluations through it take no lock.
pub struct Scratch {
    mem: Vec<f64>,
}

/// A compiled program: machine code where the compiler gives it, else the interpreter.
pub struct Function {
    program: Program,
    code: Option<MachineCode>,
    /// The memory of [`Function::eval`] (shared callers take turns).
    shared: Mutex<Scratch>,
}

impl Function {
    /// Compile `program` with `compiler`. Never fails: without machine code the program is
    /// interpreted.
    pub fn compile(program: Program, compiler: &dyn Compiler) -> Self {
        let code = compiler.machine_code(&program);
        let mem = code
            .as_ref()
            .map(|c| c.template.clone())
            .unwrap_or_default();
        Function {
            program,
            code,
            shared: Mutex::new(Scratch { mem }),
        }
    }

    /// True when the program runs as machine code.
    pub fn is_machine_code(&self) -> bool {
        self.code.is_some()
    }

    pub fn program(&self) -> &Program {
        &self.program
    }

    /// A working memory for [`Function::eval_in`].
    pub fn scratch(&self) -> Scratch {
        Scratch {
            mem: self
                .code
                .as_ref()
                .map(|c| c.template.clone())
                .unwrap_or_default(),
        }
    }

    /// Evaluate at `inputs` (`n_inputs`), writing `out` (`n_outputs`), in `scratch` (one of
    /// this function's): no lock, so evaluators on many threads run at once.
    #[inline]
    pub fn eval_in(&self, scratch: &mut Scratch, inputs: &[f64], out: &mut [f64]) {
        let (ni, no) = (self.program.n_inputs, self.program.n_outputs);
        match &self.code {
            Some(m) => {
                let mem = &mut scratch.mem;
                debug_assert_eq!(mem.len(), m.template.len());
                mem[m.first_input..m.first_input + ni].copy_from_slice(&inputs[..ni]);
                // the code reads `params` and reads and writes `mem` only (symjit's ABI)
                (m.func)(
                    mem.as_mut_ptr() as *const f64,
                    std::ptr::null(),
                    0,
                    m.params.as_ptr(),
                );
                out[..no].copy_from_slice(&mem[m.first_output..m.first_output + no]);
            }
            None => self.program.eval(inputs, out),
        }
    }

    /// Evaluate at `inputs` (`n_inputs`), writing `out` (`n_outputs`), in the function's own
    /// memory (callers on several threads take turns).
    pub fn eval(&self, inputs: &[f64], out: &mut [f64]) {
        let mut guard = self.shared.lock().unwrap_or_else(|e| e.into_inner());
        self.eval_in(&mut guard, inputs, out);
    }
}

/// A test program of one input t: `[sin(t)·t + t², atan2(t, 2), x₀ = exp(−t), sqrt(x₀) + x₀]`,
/// the temporary shared (the tests of this crate and of `poinsot-jit`).
#[doc(hidden)]
pub fn sample_program() -> Program {
    let (c, v): (Vec<i64>, Vec<f64>) = [
        (INPUT, 0.0),
        (UNARY, 0.0), // sin
        (INPUT, 0.0),
        (MUL, 0.0),
        (INPUT, 0.0),
        (CONST, 2.0),
        (POW, 0.0),
        (ADD, 0.0),
        (OUTPUT, 0.0),
        (INPUT, 0.0),
        (CONST, 2.0),
        (BINARY, 0.0), // atan2
        (OUTPUT, 0.0),
        (CONST, -1.0),
        (INPUT, 0.0),
        (MUL, 0.0),
        (UNARY + 12, 0.0), // exp
        (STORE, 0.0),
        (LOAD, 0.0),
        (UNARY + 14, 0.0), // sqrt
        (LOAD, 0.0),
        (ADD, 0.0),
        (OUTPUT, 0.0),
    ]
    .into_iter()
    .unzip();
    Program::new(&c, &v, 1, 3).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The interpreter gives the closed forms (the machine code is held against it in
    /// `poinsot-jit`).
    #[test]
    fn the_interpreter_gives_the_closed_forms() {
        let f = Function::compile(sample_program(), &Interpreter);
        assert!(!f.is_machine_code());
        for t in [-2.0, -0.3, 0.0, 0.7, 5.0] {
            let mut b = [0.0; 3];
            f.eval(&[t], &mut b);
            let e: f64 = (-t).exp();
            let want = [t.sin() * t + t * t, t.atan2(2.0), e.sqrt() + e];
            for k in 0..3 {
                assert!(
                    (b[k] - want[k]).abs() <= 1e-15 * (1.0 + want[k].abs()),
                    "t = {t}"
                );
            }
        }
    }

    #[test]
    fn malformed_programs_are_refused() {
        assert!(Program::new(&[ADD, OUTPUT], &[0.0; 2], 1, 1).is_err()); // underflow
        assert!(Program::new(&[INPUT], &[3.0], 1, 0).is_err()); // input out of range
        assert!(Program::new(&[LOAD, OUTPUT], &[0.0; 2], 1, 1).is_err()); // unset temporary
        assert!(Program::new(&[INPUT, INPUT, OUTPUT], &[0.0; 3], 1, 1).is_err()); // leftover
        assert!(Program::new(&[INPUT, OUTPUT], &[0.0; 2], 1, 2).is_err()); // output count
        assert!(Program::new(&[99], &[0.0], 1, 0).is_err()); // unknown code
        assert!(Program::new(&[CONST], &[0.0, 1.0], 1, 0).is_err()); // lengths
    }
}
