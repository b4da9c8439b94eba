//! A model's expressions compiled to machine code at run time, without a C compiler:
//! [`Jit`], the [`Compiler`] of `poinsot-core`'s [`Program`]s over the `symjit` crate (AMD64,
//! ARM64 or RISC-V; a few hundred microseconds a program).
//!
//! A crate of its own: symjit and its dependencies take a third of a minute to build, and
//! `poinsot-core`, which needs only the [`Compiler`] contract, compiles meanwhile. Nothing here
//! holds physics: it translates whatever expressions a model brings.

use poinsot_core::expressions::{Compiler, MachineCode, Op, Program};
use symjit::{Compiled, CompilerType, Config, Expr};

/// symjit's name of each unary function (`poinsot_core::expressions::UNARY_NAMES` order).
const SYMJIT_UNARY: [&str; 17] = [
    "sin", "cos", "tan", "arcsin", "arccos", "arctan", "sinh", "cosh", "tanh", "arcsinh",
    "arccosh", "arctanh", "exp", "ln", "root", "abs", "sign",
];
/// ... and of each binary function (`BINARY_NAMES` order).
const SYMJIT_BINARY: [&str; 3] = ["atan2", "min", "max"];

/// The compiler of programs to machine code (CSE, no fused multiply-adds, so that the
/// results do not depend on the CPU); it declines (the program is interpreted) where symjit
/// cannot give machine code.
pub struct Jit;

impl Compiler for Jit {
    fn machine_code(&self, program: &Program) -> Option<MachineCode> {
        // symjit's option bits: CSE (0x4), COMPACT (0x1000), STABLE_MATH (0x0800_0000), and
        // opt level 1; an explicit configuration, so that no `symjit.toml` of the working
        // directory is read.
        let opt = 0x4 | 0x1000 | 0x0800_0000 | (1 << 8);
        let config = Config::new(CompilerType::Native, opt).ok()?;
        let (inputs, outputs) = to_symjit(program);
        let mut compiler = symjit::Compiler::with_config(config);
        let mut app = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            compiler.compile(&inputs, &outputs)
        }))
        .ok()?
        .ok()?;
        if app.count_states != program.n_inputs || app.count_obs != program.n_outputs {
            return None;
        }
        // Only the machine code (with its own memory) is kept; the rest of the application
        // (the compiler's graph) is dropped here.
        let code = app.compiled.take()?;
        let template = code.mem().to_vec();
        let func = code.func();
        // SAFETY: symjit's code reads `params` and reads and writes the memory it is given
        // (a copy of its own), with the states (inputs) at `first_state` and the observables
        // (outputs) at `first_obs`; `code` owns the executable memory.
        unsafe {
            MachineCode::new(
                program,
                Box::new(code),
                func,
                app.params.clone(),
                template,
                app.first_state,
                app.first_obs,
            )
        }
    }
}

/// The program as symjit expressions: the inputs (variables) and the outputs.
fn to_symjit(program: &Program) -> (Vec<Expr>, Vec<Expr>) {
    let inputs: Vec<Expr> = (0..program.n_inputs)
        .map(|i| Expr::var(&format!("x{i}")))
        .collect();
    let mut temps: Vec<Expr> = vec![Expr::from(0.0); program.n_temps()];
    let mut stack: Vec<Expr> = Vec::new();
    let mut outs = Vec::with_capacity(program.n_outputs);
    for op in program.ops() {
        match *op {
            Op::Const(c) => stack.push(Expr::from(c)),
            Op::Input(i) => stack.push(inputs[i].clone()),
            Op::Load(i) => stack.push(temps[i].clone()),
            Op::Store(i) => temps[i] = stack.pop().expect("checked"),
            Op::Output => outs.push(stack.pop().expect("checked")),
            Op::Unary(f) => {
                let x = stack.pop().expect("checked");
                stack.push(Expr::unary(SYMJIT_UNARY[f], &x));
            }
            Op::Add | Op::Mul | Op::Pow | Op::Binary(_) => {
                let b = stack.pop().expect("checked");
                let a = stack.pop().expect("checked");
                let name = match *op {
                    Op::Add => "plus",
                    Op::Mul => "times",
                    Op::Pow => "power",
                    Op::Binary(f) => SYMJIT_BINARY[f],
                    _ => unreachable!(),
                };
                stack.push(Expr::binary(name, &a, &b));
            }
        }
    }
    (inputs, outs)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use poinsot_core::expressions::{
        sample_program, Function, BINARY, BINARY_NAMES, INPUT, OUTPUT, UNARY, UNARY_NAMES,
    };

    /// The machine code equals the interpreter and the closed forms.
    #[test]
    fn machine_code_equals_the_interpreter_and_the_closed_form() {
        let f = Function::compile(sample_program(), &Jit);
        #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
        assert!(f.is_machine_code());
        for t in [-2.0, -0.3, 0.0, 0.7, 5.0] {
            let mut a = [0.0; 3];
            let mut b = [0.0; 3];
            f.eval(&[t], &mut a);
            f.program().eval(&[t], &mut b);
            let e: f64 = (-t).exp();
            let want = [t.sin() * t + t * t, t.atan2(2.0), e.sqrt() + e];
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() <= 1e-15 * (1.0 + b[k].abs()), "t = {t}");
                assert!(
                    (b[k] - want[k]).abs() <= 1e-15 * (1.0 + want[k].abs()),
                    "t = {t}"
                );
            }
        }
    }

    #[test]
    fn every_function_compiles_and_agrees() {
        for k in 0..UNARY_NAMES.len() {
            let p = Program::new(&[INPUT, UNARY + k as i64, OUTPUT], &[0.0; 3], 1, 1).unwrap();
            let f = Function::compile(p, &Jit);
            let x = if k == 10 { 1.7 } else { 0.4 }; // acosh needs x ≥ 1
            let (mut a, mut b) = ([0.0], [0.0]);
            f.eval(&[x], &mut a);
            f.program().eval(&[x], &mut b);
            assert!(
                (a[0] - b[0]).abs() <= 1e-15 * (1.0 + b[0].abs()),
                "{}",
                UNARY_NAMES[k]
            );
        }
        for k in 0..BINARY_NAMES.len() {
            let p = Program::new(
                &[INPUT, INPUT, BINARY + k as i64, OUTPUT],
                &[0.0, 1.0, 0.0, 0.0],
                2,
                1,
            )
            .unwrap();
            let f = Function::compile(p, &Jit);
            for (x, y) in [(0.3, -1.2), (-2.0, 0.5)] {
                let (mut a, mut b) = ([0.0], [0.0]);
                f.eval(&[x, y], &mut a);
                f.program().eval(&[x, y], &mut b);
                assert_eq!(a[0], b[0], "{}", BINARY_NAMES[k]);
            }
        }
    }
}
