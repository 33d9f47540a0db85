//! [`tasks!`](crate::tasks): the app's software tasks declared once. Each
//! entry names a task, its priority, the function a run calls and the
//! words of its row in the task table; the macro makes from it the `Task`
//! enum (its doc is the table), `Task::ALL`, `task_of`, the priorities
//! (`taut_logic::sched::TaskId`) and `Task::run`, the dispatch. Two ids
//! may run one function (the urgent and the background refill).

/// Declares the software tasks, in id order (the order in which the
/// interrupts' spawns that came together are admitted): see the module
/// doc. Invoke once, at the app's crate root.
#[macro_export]
macro_rules! tasks {
    ($(
        $name:ident {
            priority: $prio:literal,
            runs: $run:path,
            does: $does:literal,
            input: $input:literal,
            output: $output:literal $(,)?
        }
    ),* $(,)?) => {
        #[doc = concat!(
            "The software tasks, in id order: run to completion from the ",
            "dispatcher, highest priority first, FIFO within a priority.\n\n",
            "| task | priority | input | output |\n",
            "| --- | --- | --- | --- |\n",
            $(
                "| `", stringify!($name), "` ", $does, " | ", stringify!($prio),
                " | ", $input, " | ", $output, " |\n",
            )*
        )]
        #[derive(Clone, Copy, PartialEq, Eq)]
        enum Task {
            $(
                #[doc = $does]
                $name,
            )*
        }

        impl Task {
            /// Every task, in id order (`Task::X as u8` indexes it).
            const ALL: [Task; [$(stringify!($name)),*].len()] = [$(Task::$name),*];
            /// Priority levels: the highest priority, plus one.
            const LEVELS: usize = {
                let (mut max, mut i) = (0, 0);
                while i < Task::ALL.len() {
                    if Task::ALL[i].priority_of() > max {
                        max = Task::ALL[i].priority_of();
                    }
                    i += 1;
                }
                max as usize + 1
            };

            /// A match: a table would sit in SRAM.
            const fn priority_of(self) -> u8 {
                match self {
                    $(Task::$name => $prio,)*
                }
            }

            /// Run the task once.
            #[inline(always)]
            fn run(self) {
                match self {
                    $(Task::$name => $run(),)*
                }
            }
        }

        /// Each task's id, a pattern for `task_of`'s match.
        #[allow(non_upper_case_globals)]
        mod task_id {
            $(pub const $name: u8 = super::Task::$name as u8;)*
        }

        /// `Task::ALL[id]`, worked out: a table would sit in SRAM.
        const fn task_of(id: u8) -> Task {
            match id {
                $(task_id::$name => Task::$name,)*
                _ => unreachable!(),
            }
        }

        const _: () = {
            assert!(Task::ALL.len() <= 16, "interrupt spawns are a bit per task");
            let mut i = 0;
            while i < Task::ALL.len() {
                assert!(Task::ALL[i] as usize == i);
                assert!(task_of(i as u8) as usize == i);
                i += 1;
            }
        };

        impl taut_logic::sched::TaskId for Task {
            const COUNT: usize = Task::ALL.len();
            fn index(self) -> usize {
                self as usize
            }
            fn priority(self) -> u8 {
                self.priority_of()
            }
        }
    };
}
