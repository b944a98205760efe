//! Options shared by every command that runs the pipeline: the library's stage options
//! ([`STAGE_OPTIONS`]), each made a flag with its help and default. Nothing here names a
//! default or a rule.

use anyhow::Result;
use clap::error::ErrorKind;
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use neurotex::options::{OptionKind, OptionSpec, StageOptions, STAGE_OPTIONS};

/// Stage parameters; defaults are the paper's values (or, where it gives none, a choice
/// whose reasons docs/decisions/ gives).
#[derive(Debug, Clone, Default)]
pub struct StageArgs {
    /// The stage options as given, unchecked.
    pub options: StageOptions,
}

/// The flag of one stage option.
fn flag(spec: &'static OptionSpec) -> Arg {
    let arg = Arg::new(spec.name)
        .long(spec.flag())
        .help(spec.help.trim_end_matches('.'));
    let action = match spec.kind {
        OptionKind::Flag => return arg.action(ArgAction::SetTrue),
        // `--distances 1 --distances 2,4` is `1,2,4`.
        OptionKind::Counts => ArgAction::Append,
        _ => ArgAction::Set,
    };
    let arg = arg
        .value_name(spec.name.to_uppercase())
        .action(action)
        .allow_negative_numbers(true)
        .value_parser(move |text: &str| {
            (spec.set)(&mut StageOptions::default(), text).map(|()| text.to_string())
        });
    match spec.default_text() {
        Some(text) => arg.default_value(text),
        None => arg,
    }
}

impl Args for StageArgs {
    fn augment_args(cmd: Command) -> Command {
        STAGE_OPTIONS
            .iter()
            .fold(cmd, |cmd, spec| cmd.arg(flag(spec)))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for StageArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let mut args = Self::default();
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        for spec in STAGE_OPTIONS {
            let text = match spec.kind {
                OptionKind::Flag => matches.get_flag(spec.name).then(|| "true".to_string()),
                OptionKind::Counts => matches
                    .get_many::<String>(spec.name)
                    .map(|v| v.cloned().collect::<Vec<_>>().join(",")),
                _ => matches.get_one::<String>(spec.name).cloned(),
            };
            if let Some(text) = text {
                (spec.set)(&mut self.options, &text)
                    .map_err(|e| clap::Error::raw(ErrorKind::ValueValidation, e))?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        stages: StageArgs,
    }

    #[test]
    fn flags_read_into_the_librarys_options_with_its_defaults() {
        let none = Cli::try_parse_from(["neurotex"]).unwrap();
        assert_eq!(none.stages.options, StageOptions::default());
        let args = [
            "neurotex",
            "--distances",
            "1",
            "--distances",
            "2,4",
            "--bin-ms",
            "100",
            "--symmetric",
            "--gain",
            "auto:15",
            "--cutoff",
            "-0",
        ];
        let o = Cli::try_parse_from(args).unwrap().stages.options;
        assert_eq!(o.distances, [1, 2, 4]);
        assert_eq!((o.bin_ms, o.symmetric), (100, true));
        assert_eq!(o.gain.to_string(), "auto:15");
        assert!(Cli::try_parse_from(["neurotex", "--bin-ms", "-1"]).is_err());
        assert!(Cli::try_parse_from(["neurotex", "--levels", "8", "--levels", "9"]).is_err());
    }
}
