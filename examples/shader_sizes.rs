//! What a SIMD software driver compiles for each pass of the `subdivide` stage: the size of its
//! entry point with every call inlined (lavapipe inlines every call site before it optimises,
//! and its pipeline builds take about 12–15 ms per thousand of these units on this project's
//! CPU), and the functions whose inlined copies weigh most (copies × own size).
//!
//! `cargo run --release --example shader_sizes [cylinder|sphere] [ENTRY]`: every entry point of
//! the panorama's pipelines (the sphere's with rows, as under the adaptive rules), or one with its
//! heaviest functions.

use std::collections::HashMap;
use std::io::Write;

use naga::{Block, Function, Handle, Module, Statement};
use twister::shader::{
    compose_with, ErrorTarget, EyesPerDraw, ShaderOptions, CAVE_OFF, CUBEMAP_OFF, FISHEYE_OFF, HEAD_OFF, ROWS_OFF,
    SPHERE_OFF, SUBDIVIDE,
};

/// A function's own size (expressions and statements) and the functions it calls, in order.
struct Sizes {
    own: HashMap<Handle<Function>, usize>,
    calls: HashMap<Handle<Function>, Vec<Handle<Function>>>,
}

fn walk(block: &Block, calls: &mut Vec<Handle<Function>>, statements: &mut usize) {
    for s in block.iter() {
        *statements += 1;
        match s {
            Statement::Call { function, .. } => calls.push(*function),
            Statement::Block(b) => walk(b, calls, statements),
            Statement::If { accept, reject, .. } => {
                walk(accept, calls, statements);
                walk(reject, calls, statements);
            }
            Statement::Loop { body, continuing, .. } => {
                walk(body, calls, statements);
                walk(continuing, calls, statements);
            }
            Statement::Switch { cases, .. } => cases.iter().for_each(|c| walk(&c.body, calls, statements)),
            _ => {}
        }
    }
}

impl Sizes {
    fn of(module: &Module) -> Sizes {
        let (mut own, mut calls) = (HashMap::new(), HashMap::new());
        for (h, f) in module.functions.iter() {
            let (mut c, mut n) = (Vec::new(), 0);
            walk(&f.body, &mut c, &mut n);
            own.insert(h, f.expressions.len() + n);
            calls.insert(h, c);
        }
        Sizes { own, calls }
    }

    /// Inlined copies of each function reached from `roots` (one per call path).
    fn copies(&self, roots: &[Handle<Function>]) -> HashMap<Handle<Function>, usize> {
        let mut copies = HashMap::new();
        let mut stack: Vec<Handle<Function>> = roots.to_vec();
        while let Some(h) = stack.pop() {
            *copies.entry(h).or_default() += 1;
            stack.extend(self.calls[&h].iter().copied());
        }
        copies
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sphere = args.get(1).is_some_and(|a| a == "sphere");
    let only = args.get(2);
    let stand_ins = if sphere {
        vec![FISHEYE_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF]
    } else {
        vec![ROWS_OFF, SPHERE_OFF, FISHEYE_OFF, HEAD_OFF, CUBEMAP_OFF, CAVE_OFF]
    };
    let options = ShaderOptions { error_target: ErrorTarget::Float, eyes: EyesPerDraw::One };
    // Written with errors ignored: a closed pipe (`| head`) ends the listing quietly.
    let mut out = std::io::stdout().lock();
    for entry in SUBDIVIDE.entry_points.iter().map(|e| e.name).filter(|e| only.is_none_or(|o| o == e)) {
        let source = compose_with(&SUBDIVIDE.file_of(Some(entry)), options, &stand_ins);
        let module = match naga::front::wgsl::parse_str(&source) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{entry}: {}", e.emit_to_string(&source));
                std::process::exit(1);
            }
        };
        let sizes = Sizes::of(&module);
        let ep = module.entry_points.iter().find(|e| e.name == entry).expect("the pass's entry point");
        let (mut roots, mut statements) = (Vec::new(), 0);
        walk(&ep.function.body, &mut roots, &mut statements);
        let copies = sizes.copies(&roots);
        let inlined: usize =
            ep.function.expressions.len() + statements + copies.iter().map(|(h, n)| n * sizes.own[h]).sum::<usize>();
        let _ = writeln!(out, "{entry:<20} {inlined:>7}");
        if only.is_some() {
            let mut heavy: Vec<_> = copies.iter().map(|(h, &n)| (n * sizes.own[h], n, sizes.own[h], *h)).collect();
            heavy.sort_by_key(|h| std::cmp::Reverse(h.0));
            for (total, n, own, h) in heavy.into_iter().take(25) {
                let name = module.functions[h].name.clone().unwrap_or_default();
                let _ = writeln!(out, "  {total:>6} = {n:>3} × {own:>4}  {name}");
            }
        }
    }
}
