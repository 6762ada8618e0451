//! Fuzzed inputs (issue 21): generated malformed and extreme case, cantilever and sample files
//! and option values, pushed through the command line's parsing (clap, as `drumroll simulate`
//! and `drumroll continue` parse them), the option table, file loading and model construction,
//! then a short steady orbit and a few continuation points with capped steps, and an output
//! file written. Nothing may panic or take long, no partial or probe file may be left, and
//! every rejection must name the file or option, the field and the allowed range (or the
//! expected type or fields).
//!
//! Sizes a file sets are drawn past their limits: a cantilever file has up to 60 modes
//! (`afm::MAX_MODES` is 50; a model of more than [`MAX_ORBIT_MODES`] modes is built and checked
//! but not integrated, so that an input stays quick). Files may start with a UTF-8 byte-order
//! mark, and a case file's references may be `.` or a name that is no file.
//!
//! To cover a new input file (a scan line file, a measurement CSV, a new contact law's sample
//! object): add a generator beside [`cantilever_text`] (clean values near typical ones, and
//! when not clean the malformed, extreme and wrong-typed values of [`json_number`] and
//! [`json_name`]), a field of [`Input`] for it, write it in [`run_one`] next to `lever.json`,
//! and push it through the command's own parsing and checks there, with [`check_rejection`]
//! on every refusal.
//!
//! `cargo test --release -p drumroll --test fuzz_inputs` runs [`DEFAULT_CASES`] inputs;
//! `DRUMROLL_FUZZ_CASES=100000 cargo test --release -p drumroll --test fuzz_inputs -- --nocapture`
//! is the long run (it prints the count, the rejections and the slowest input).

use std::path::Path;
use std::time::{Duration, Instant};

use afm::{approach_diagram, steady_orbit, OrbitStart, SteadyOrbitSettings, TappingModel};
use clap::Parser;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// Inputs per `cargo test` run (about 20 s in release on a shared 2-core machine).
const DEFAULT_CASES: u32 = 2000;

/// The longest one input may take, steady orbit and continuation included: a hang shows
/// as a failure. The caps below keep a capped run well under it.
const MAX_TIME_PER_INPUT: Duration = Duration::from_secs(10);

/// The most modes a generated model is integrated with (more: built and checked only).
const MAX_ORBIT_MODES: usize = 4;

/// `drumroll simulate`'s options, parsed as the binary parses them.
#[derive(Debug, Parser)]
struct SimulateCommand {
    #[command(flatten)]
    args: drumroll::simulate::SimulateArgs,
}

/// `drumroll continue`'s options, parsed as the binary parses them.
#[derive(Debug, Parser)]
struct ContinueCommand {
    #[command(flatten)]
    args: drumroll::continue_diagram::ContinueArgs,
}

/// A number as written in a file or typed as an option: near `typical` when `clean`,
/// otherwise also extreme, negative, zero, out of the f64 range, or off by a unit prefix.
fn number(typical: f64, clean: bool) -> BoxedStrategy<String> {
    let near = (-0.3f64..0.3).prop_map(move |e| format!("{}", typical * 10f64.powf(e)));
    if clean {
        return near.boxed();
    }
    prop_oneof![
        4 => near,
        2 => (-15i32..=15, 1.0f64..10.0, any::<bool>()).prop_map(|(e, m, negative)| {
            let value = m * 10f64.powi(e);
            format!("{:e}", if negative { -value } else { value })
        }),
        2 => prop::sample::select(vec![1e-9, 1e-6, 1e-3, 1e3, 1e6, 1e9, -1.0, 0.0])
            .prop_map(move |factor| format!("{}", typical * factor)),
        1 => prop::sample::select(vec![
            "0", "-0", "1e400", "-1e400", "1e-400", "1.7976931348623157e308", "5e-324", "-1",
        ])
        .prop_map(String::from),
    ]
    .boxed()
}

/// A JSON value for a numeric field: mostly a number, sometimes another type or not JSON.
fn json_number(typical: f64, clean: bool) -> BoxedStrategy<Option<String>> {
    if clean {
        return number(typical, true).prop_map(Some).boxed();
    }
    prop_oneof![
        12 => number(typical, false).prop_map(Some),
        1 => prop::sample::select(vec![
            "\"abc\"", "null", "[]", "{}", "true", "NaN", "Infinity", "\"1.0\"", "[1, 2]",
        ])
        .prop_map(|token| Some(token.to_string())),
        1 => Just(None),
    ]
    .boxed()
}

/// A JSON value for a name or reference field.
fn json_name(choices: Vec<&'static str>, clean: bool) -> BoxedStrategy<Option<String>> {
    let named = prop::sample::select(choices).prop_map(|name| Some(format!("\"{name}\"")));
    if clean {
        return named.boxed();
    }
    prop_oneof![
        8 => named,
        1 => prop::sample::select(vec!["\"\"", "\" padded \"", "3", "null", "\"nolever\""])
            .prop_map(|token| Some(token.to_string())),
        1 => Just(None),
    ]
    .boxed()
}

/// `{"key": value, ...}` of the fields present, with an unknown field sometimes.
fn object(fields: Vec<(&'static str, Option<String>)>, extra: bool) -> String {
    let mut members: Vec<String> = fields
        .into_iter()
        .filter_map(|(key, value)| value.map(|value| format!("\"{key}\": {value}")))
        .collect();
    if extra {
        members.push(String::from("\"colour\": \"blue\""));
    }
    format!("{{{}}}", members.join(", "))
}

/// Damage a file's text: cut it short, put a stray character in it, or (accepted) start it
/// with a UTF-8 byte-order mark.
fn corrupt(text: String, damage: Option<(u8, usize)>) -> String {
    let Some((kind, at)) = damage else {
        return text;
    };
    if kind % 7 == 6 {
        return format!("\u{feff}{text}");
    }
    let at = at % (text.len() + 1);
    let at = (0..=at)
        .rev()
        .find(|i| text.is_char_boundary(*i))
        .unwrap_or(0);
    match kind % 3 {
        0 => text[..at].to_string(),
        1 => format!("{}}}{}", &text[..at], &text[at..]),
        _ => format!("{}\u{e9}x{}", &text[..at], &text[at..]),
    }
}

/// `count` valid modes: `f_n = 9.3 n^2` kHz, `k_n = 0.036 n^4` N/m (above the typical range
/// from mode 13 on), ratios 1.
fn many_modes(count: usize) -> String {
    (1..=count)
        .map(|n| {
            let n = n as f64;
            format!(
                "{{\"stiffness_n_per_m\": {}, \"frequency_khz\": {}, \"quality_factor\": 1.2, \
                 \"optical_sensitivity\": 1, \"force_ratio\": 1}}",
                0.036 * n.powi(4),
                9.3 * n * n
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A cantilever file's text: up to four modes near the Biolever's and beyond, or (rarely)
/// 5 to 60 valid modes, past the limit of 50.
fn cantilever_text(clean: bool) -> BoxedStrategy<String> {
    let typical_modes = [
        (0.036, 9.3, 1.2, 1.0, 1.0),
        (1.4, 72.0, 2.0, 3.47, -0.554),
        (10.0, 200.0, 4.0, 5.0, 0.3),
        (40.0, 400.0, 6.0, 7.0, -0.2),
    ];
    let mode = move |index: usize| {
        let (k, f, q, chi, r) = typical_modes[index];
        // Mode 1's ratios are exactly 1 in a valid file.
        let ratio = |typical: f64| {
            if clean && index == 0 {
                Just(Some(String::from("1"))).boxed()
            } else {
                json_number(typical, clean)
            }
        };
        (
            json_number(k, clean),
            json_number(f, clean),
            json_number(q, clean),
            ratio(chi),
            ratio(r),
        )
            .prop_map(|(k, f, q, chi, r)| {
                object(
                    vec![
                        ("stiffness_n_per_m", k),
                        ("frequency_khz", f),
                        ("quality_factor", q),
                        ("optical_sensitivity", chi),
                        ("force_ratio", r),
                    ],
                    false,
                )
            })
    };
    let count = if clean { 1usize..=3 } else { 0usize..=4 };
    (
        count,
        mode(0),
        mode(1),
        mode(2),
        mode(3),
        json_number(30.0, clean),
        json_number(0.1, clean),
        json_number(130.0, clean),
        json_number(0.3, clean),
        json_name(vec!["lever"], clean),
        any::<bool>(),
        prop::option::weighted(0.05, 5usize..=60),
    )
        .prop_map(
            move |(count, m0, m1, m2, m3, radius, mass, modulus, poisson, name, extra, many)| {
                let modes = match many {
                    Some(many) => many_modes(many),
                    None => [m0, m1, m2, m3][..count].join(", "),
                };
                object(
                    vec![
                        ("name", name),
                        ("tip_radius_nm", radius),
                        ("tip_mass_ratio", mass),
                        ("tip_youngs_modulus_gpa", modulus),
                        ("tip_poisson_ratio", poisson),
                        ("modes", Some(format!("[{modes}]"))),
                    ],
                    extra && !clean,
                )
            },
        )
        .boxed()
}

/// A sample file's text.
fn sample_text(clean: bool) -> BoxedStrategy<String> {
    (
        json_name(vec!["surface"], clean),
        json_number(60.0, clean),
        json_number(0.3, clean),
        any::<bool>(),
    )
        .prop_map(move |(name, modulus, poisson, extra)| {
            object(
                vec![
                    ("name", name),
                    ("youngs_modulus_gpa", modulus),
                    ("poisson_ratio", poisson),
                ],
                extra && !clean,
            )
        })
        .boxed()
}

/// A case file's text, naming the generated cantilever and sample files or built-in ones.
fn case_text(clean: bool) -> BoxedStrategy<String> {
    (
        json_name(
            vec![
                "lever.json",
                "biolever",
                "maclever",
                "missing.json",
                ".",
                "lever",
            ],
            clean,
        ),
        json_name(
            vec!["surface.json", "mica", "soft", "purple-membrane"],
            clean,
        ),
        json_number(10.0, clean),
        prop::option::of(json_number(9.3, clean)),
        json_name(vec!["generated"], clean),
        any::<bool>(),
    )
        .prop_map(move |(cantilever, sample, a0, frequency, name, extra)| {
            object(
                vec![
                    ("name", name),
                    ("cantilever", cantilever),
                    ("sample", sample),
                    ("free_amplitude_nm", a0),
                    ("drive_frequency_khz", frequency.flatten()),
                ],
                extra && !clean,
            )
        })
        .boxed()
}

/// An option's value as typed: a number (near `typical` when `clean`) or not one.
fn option_value(typical: f64, clean: bool) -> BoxedStrategy<String> {
    if clean {
        return number(typical, true);
    }
    prop_oneof![
        10 => number(typical, false),
        1 => prop::sample::select(vec!["abc", "NaN", "inf", "-inf", "", "1e400", "--", "1,5"])
            .prop_map(String::from),
    ]
    .boxed()
}

/// One generated input: files, how the model is chosen, and options.
#[derive(Debug, Clone)]
struct Input {
    cantilever: String,
    sample: String,
    case: String,
    /// 0: `--case FILE`; 1: `--cantilever FILE --sample FILE --a0`; 2: a built-in case.
    model_choice: u8,
    a0: Option<String>,
    drive_frequency: Option<String>,
    z: String,
    amplitude_ratio: Option<String>,
    floor: Option<String>,
    max_step: Option<String>,
    min_amplitude_ratio: Option<String>,
    max_points: Option<String>,
    /// 0: `out.svg` in the directory; 1: in a missing directory; 2: the wrong extension.
    plot: u8,
}

fn input() -> impl Strategy<Value = Input> {
    any::<bool>().prop_flat_map(|clean| {
        let damage = if clean {
            Just(None).boxed()
        } else {
            prop::option::weighted(0.1, (any::<u8>(), any::<usize>())).boxed()
        };
        (
            (
                cantilever_text(clean),
                sample_text(clean),
                case_text(clean),
                damage.clone(),
                damage.clone(),
                damage,
            ),
            0u8..3,
            (
                prop::option::weighted(0.4, option_value(10.0, clean)),
                prop::option::weighted(0.3, option_value(9.3, clean)),
                option_value(5.0, clean),
                prop::option::weighted(0.15, option_value(0.5, clean)),
            ),
            (
                prop::option::weighted(0.3, option_value(5.0, clean)),
                prop::option::weighted(0.3, option_value(0.05, clean)),
                prop::option::weighted(0.3, option_value(0.3, clean)),
                prop::option::weighted(0.3, option_value(50.0, clean)),
            ),
            if clean { 0u8..1 } else { 0u8..3 },
        )
            .prop_map(
                |(
                    (cantilever, sample, case, d1, d2, d3),
                    model_choice,
                    (a0, drive_frequency, z, amplitude_ratio),
                    (floor, max_step, min_amplitude_ratio, max_points),
                    plot,
                )| Input {
                    cantilever: corrupt(cantilever, d1),
                    sample: corrupt(sample, d2),
                    case: corrupt(case, d3),
                    model_choice,
                    a0,
                    drive_frequency,
                    z,
                    amplitude_ratio,
                    floor,
                    max_step,
                    min_amplitude_ratio,
                    max_points,
                    plot,
                },
            )
    })
}

/// What one input ended in.
#[derive(Debug, Default)]
struct Tally {
    inputs: u64,
    refused_by_clap: u64,
    refused: u64,
    models: u64,
    orbits: u64,
    orbit_failures: u64,
    diagrams: u64,
    many_modes: u64,
    slowest: Duration,
}

/// The text of an error with its causes, as `main` prints it.
fn chain(error: &anyhow::Error) -> String {
    error
        .chain()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(": ")
}

/// A rejection must name where (an option, or a file or built-in name), what (a field or an
/// option; for a JSON syntax error, its line and column) and what is allowed (a range, the
/// expected type or fields, or the known names).
fn check_rejection(message: &str, sources: &[&str]) -> Result<(), TestCaseError> {
    let names_option = message.contains("--");
    let names_source = names_option || sources.iter().any(|source| message.contains(source));
    // A syntax error is in no field: its line and column locate it.
    let syntax = message.contains(" at line ") && message.contains(" column ");
    let names_field = names_option
        || syntax
        || message.contains("field `")
        || message.contains("unknown ")
        || message.contains("cannot read")
        || message.contains("cannot write there");
    let names_range = message.contains("allowed")
        || message.contains("expected")
        || message.contains("built-in")
        || message.contains("cannot read")
        || message.contains("missing field")
        || message.contains("cannot write there")
        || syntax;
    prop_assert!(
        names_source && names_field && names_range,
        "a rejection that does not name file or option, field and range: {message}"
    );
    prop_assert!(
        !message.contains(".partial") && !message.contains(".probe"),
        "{message}"
    );
    Ok(())
}

/// The files of `dir` that a run must never leave behind.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .map(|entry| entry.file_name().to_string_lossy().into_owned())
                .filter(|name| name.contains(".partial") || name.ends_with(".probe"))
                .collect()
        })
        .unwrap_or_default()
}

/// Settings that bound the time of one steady orbit whatever the model: few periods, few
/// Newton iterations, few steps per flow-map call.
fn capped_orbit_settings() -> SteadyOrbitSettings {
    let mut settings = SteadyOrbitSettings::default();
    settings.integration.max_steps = 20_000;
    settings.integration.max_events = 2_000;
    settings.transient_periods = 2;
    settings.recurrence_periods = 4;
    settings.max_multiplicity = 2;
    settings.newton.max_iterations = 4;
    settings
}

/// The words of `drumroll simulate` for `input` (files at `lever`, `surface`, `case`, plot
/// at `plot`), and the model's options alone (for `continue`).
fn command_words(
    input: &Input,
    lever: &str,
    surface: &str,
    case: &str,
    plot: &str,
) -> (Vec<String>, Vec<String>) {
    let mut words: Vec<String> = vec![String::from("simulate")];
    let push = |words: &mut Vec<String>, option: &str, value: &Option<String>| {
        if let Some(value) = value {
            words.push(format!("--{option}={value}"));
        }
    };
    match input.model_choice {
        0 => push(&mut words, "case", &Some(case.to_string())),
        1 => {
            push(&mut words, "cantilever", &Some(lever.to_string()));
            push(&mut words, "sample", &Some(surface.to_string()));
            let a0 = input.a0.clone().unwrap_or_else(|| "10".into());
            push(&mut words, "a0", &Some(a0));
        }
        _ => push(&mut words, "case", &Some(String::from("biolever-mica"))),
    }
    if input.model_choice != 1 {
        push(&mut words, "a0", &input.a0);
    }
    push(&mut words, "drive-frequency", &input.drive_frequency);
    let model_words = words[1..].to_vec();
    match &input.amplitude_ratio {
        Some(ratio) => push(&mut words, "amplitude-ratio", &Some(ratio.clone())),
        None => push(&mut words, "z", &Some(input.z.clone())),
    }
    push(&mut words, "plot", &Some(plot.to_string()));
    (words, model_words)
}

/// Push one input through parsing, checks, model, a short orbit and diagram, and an output.
fn run_one(input: &Input, dir: &Path, tally: &mut Tally) -> Result<(), TestCaseError> {
    let started = Instant::now();
    tally.inputs += 1;
    let lever = dir.join("lever.json");
    let surface = dir.join("surface.json");
    let case = dir.join("case.json");
    std::fs::write(&lever, &input.cantilever).expect("write");
    std::fs::write(&surface, &input.sample).expect("write");
    std::fs::write(&case, &input.case).expect("write");
    let (lever, surface, case) = (
        lever.display().to_string(),
        surface.display().to_string(),
        case.display().to_string(),
    );
    let plot = match input.plot {
        0 => dir.join("out.svg"),
        1 => dir.join("missing").join("out.svg"),
        _ => dir.join("out.txt"),
    }
    .display()
    .to_string();

    let (words, model_words) = command_words(input, &lever, &surface, &case, &plot);
    let sources = [
        lever.as_str(),
        surface.as_str(),
        case.as_str(),
        "biolever",
        "maclever",
        "mica",
    ];

    let simulate = match SimulateCommand::try_parse_from(&words) {
        Ok(command) => command.args,
        Err(error) => {
            // clap refuses what is not a number, naming the option.
            tally.refused_by_clap += 1;
            let message = error.to_string();
            prop_assert!(message.contains("'--"), "{message}");
            return Ok(());
        }
    };
    let checked = drumroll::simulate::check_orbit_options(simulate.z, simulate.amplitude_ratio)
        .and_then(|()| {
            simulate
                .plot
                .as_ref()
                .map(|path| drumroll::model_args::output_path(path, "svg", "--plot"))
                .transpose()
        })
        .and_then(|plot_path| Ok((plot_path, simulate.model.model()?)));
    let (plot_path, (resolved, model)) = match checked {
        Ok(found) => found,
        Err(error) => {
            tally.refused += 1;
            if std::env::var_os("DRUMROLL_FUZZ_SHOW").is_some() {
                println!("refused: {}", chain(&error));
            }
            check_rejection(&chain(&error), &sources)?;
            prop_assert!(leftovers(dir).is_empty(), "{:?}", leftovers(dir));
            return Ok(());
        }
    };
    tally.models += 1;
    if model.mode_count() > MAX_ORBIT_MODES {
        tally.many_modes += 1;
        prop_assert!(
            model.mode_count() <= afm::MAX_MODES,
            "{} modes",
            model.mode_count()
        );
        return Ok(());
    }
    let settings = capped_orbit_settings();
    if let Some(z) = simulate.z {
        let allowed = drumroll::option_ranges::separation_for(model.free_amplitude_nm()).check(z);
        match allowed {
            Err(error) => {
                tally.refused += 1;
                check_rejection(&chain(&error), &sources)?;
            }
            Ok(()) => match steady_orbit(&model, z, OrbitStart::Approach, &settings) {
                Ok(orbit) => {
                    tally.orbits += 1;
                    let json = drumroll::simulate::orbit_json(&resolved.name, &model, &orbit);
                    let text = serde_json::to_string(&json).expect("JSON of an orbit");
                    if let Some(path) = &plot_path {
                        drumroll::output::write_atomically(path, text.as_bytes())
                            .expect("a checked path is writable");
                    }
                }
                Err(_) => tally.orbit_failures += 1,
            },
        }
    }
    if tally.models.is_multiple_of(8) {
        run_diagram(input, &model_words, &model, &sources, tally)?;
    }
    prop_assert!(leftovers(dir).is_empty(), "{:?}", leftovers(dir));
    let elapsed = started.elapsed();
    tally.slowest = tally.slowest.max(elapsed);
    prop_assert!(
        elapsed <= MAX_TIME_PER_INPUT,
        "{elapsed:?} for one input: {input:?}"
    );
    Ok(())
}

/// `continue`'s options on the same model, then four branch points with capped orbits.
fn run_diagram(
    input: &Input,
    model_words: &[String],
    model: &TappingModel,
    sources: &[&str],
    tally: &mut Tally,
) -> Result<(), TestCaseError> {
    let mut words = vec![String::from("continue")];
    words.extend(model_words.iter().cloned());
    for (option, value) in [
        ("floor", &input.floor),
        ("max-step", &input.max_step),
        ("min-amplitude-ratio", &input.min_amplitude_ratio),
        ("max-points", &input.max_points),
    ] {
        if let Some(value) = value {
            words.push(format!("--{option}={value}"));
        }
    }
    let args = match ContinueCommand::try_parse_from(&words) {
        Ok(command) => command.args,
        Err(error) => {
            tally.refused_by_clap += 1;
            let message = error.to_string();
            prop_assert!(message.contains("'--"), "{message}");
            return Ok(());
        }
    };
    match drumroll::continue_diagram::diagram_settings(&args, model) {
        Err(error) => {
            tally.refused += 1;
            check_rejection(&chain(&error), sources)?;
        }
        Ok(mut settings) => {
            settings.orbit = capped_orbit_settings();
            settings.max_points = settings.max_points.min(4);
            // A diagram may end early (an error, a failed corrector): never a panic.
            let _ = approach_diagram(model, &settings);
            tally.diagrams += 1;
        }
    }
    Ok(())
}

#[test]
fn generated_inputs_never_panic_hang_or_leave_files_and_every_rejection_is_named() {
    let cases = std::env::var("DRUMROLL_FUZZ_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(DEFAULT_CASES);
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 200,
        ..Config::default()
    });
    let tally = std::cell::RefCell::new(Tally::default());
    let started = Instant::now();
    let result = runner.run(&input(), |input| {
        run_one(&input, dir.path(), &mut tally.borrow_mut())
    });
    let tally = tally.into_inner();
    println!(
        "fuzz_inputs: {} inputs in {:.1} s: {} refused by clap, {} refused by the checks, {} \
         models ({} of more than {MAX_ORBIT_MODES} modes, not integrated), {} orbits ({} failed \
         within the caps), {} diagrams; slowest input {:?}",
        tally.inputs,
        started.elapsed().as_secs_f64(),
        tally.refused_by_clap,
        tally.refused,
        tally.models,
        tally.many_modes,
        tally.orbits,
        tally.orbit_failures,
        tally.diagrams,
        tally.slowest
    );
    if let Err(error) = result {
        panic!("{error}");
    }
    // The generator reaches every stage, so that the run tests more than the parser.
    assert!(tally.refused > 0 && tally.models > 0, "{tally:?}");
}
