/* help.c: the command line's help, written once: `mbcc help`, `mbcc help CMD`,
 * `mbcc CMD --help` print it as text, `mbcc help --man` as the man page
 * docs/mbcc.1 (make man; tests/test_help.sh checks that the committed page
 * is current). */
#include <string.h>
#include "help.h"
#include "version.h"

typedef struct {
  const char *opt, *text;
} help_option;

typedef struct {
  const char *name, *synopsis, *summary, *description;
  help_option opts[24];
} help_command;

/* options every simulating command takes, after the model */
#define SIM_OPTIONS                                                                                    \
  {"--integrator rk4|dopri5|genalpha|auto", "the integrator (model default: dopri5)"},                  \
  {"--end T", "end time, s"}, {"--output-step H", "time between CSV rows, s"},                         \
  {"--step H", "RK4 step; DOPRI5 and generalized-alpha initial step, s"},                              \
  {"--max-step H", "largest step of the adaptive methods, s"},                                         \
  {"--rtol R, --atol A", "tolerances of the adaptive methods"},                                        \
  {"--rho-inf R", "generalized-alpha spectral radius at an infinite step, 0 to 1"},                    \
  {"--max-steps N", "give up after N steps"},                                                          \
  {"--stabilization projection|baumgarte|none", "constraint drift control"}

static const help_command commands[] = {
    {"check", "mbcc check M.yaml [--scene S]",
     "read, lower and assemble a model; print its size and structure",
     "Reports every error as FILE:LINE:COL: error: ... and exits 2; on success prints the bodies, "
     "coordinates, constraint rows (redundant ones removed), the sparse pattern of K and the plan "
     "of the emitted LDL^T.",
     {{"--scene S", "apply scene S of the model file"}}},
    {"compile", "mbcc compile M.yaml [--scene S] [-o DIR] [--real float|double] [--target host|embedded]",
     "emit the model's C code: DIR/NAME.c, DIR/NAME.h and DIR/main.c",
     "The emitted code is C99 with a fixed sparse pattern and its own LDL^T; main.c is a simulator "
     "with the model's settings, linked against libmbrt (pkg-config --cflags --libs mbcc). "
     "Without -o the code goes to generated/NAME/ in the current directory. A large model is written "
     "as several C files, listed in DIR/NAME.sources (NAME.c first): compile them all.",
     {{"--scene S", "apply scene S of the model file"},
      {"-o DIR", "the output directory (its parent must exist)"},
      {"--real float|double", "the precision of the emitted code (float: the LDL^T solver only)"},
      {"--target host|embedded", "embedded: a self-contained freestanding package for a microcontroller "
                                 "(docs/embedded.md)"},
      {"--integrator rk4|genalpha", "embedded: the fixed-step integrator of the package"},
      {"--step H", "embedded: the package's default step, s"}}},
    {"run", "mbcc run M.yaml [--scene S] [--path generated|generic] [--solver ldl|klu|dense] [OPTIONS]",
     "simulate a model: CSV results, a units file and a plot",
     "The generated path (the default) emits the model's C code, compiles it and runs it; the generic "
     "path runs the model's tables in-process without a C compiler (it has no emitted LDL^T: klu or "
     "dense). Results go to results/NAME.csv in the current directory unless -o or --results says "
     "otherwise, with NAME.csv.units (each column's unit) and NAME.png. Options given here override "
     "the model's simulation block.",
     {{"--scene S", "apply scene S of the model file"},
      {"--path generated|generic", "compiled code (default) or the in-process generic model"},
      {"--solver ldl|klu|dense", "the linear solver (default: the model's, else ldl; the generic path: klu)"},
      {"--real float|double", "the precision of the generated code"},
      {"-o FILE.csv", "the results file"},
      {"--results DIR", "the directory of the CSV, units file and plot (default: results/)"},
      {"--precision N", "significant digits in the CSV, 1 to 17 (default 12)"},
      {"--plot FILE.png|none", "the plot (default: beside the CSV)"},
      {"--columns a,b+c,...", "the columns to plot (b+c: in one panel)"},
      {"--animate", "also write the browser animation NAME.html beside the CSV (see mbcc animate)"},
      {"--body B --loads FILE.csv", "instead of the outputs, write the loads on flexible body B at its "
                                    "nodes (the joints and force elements on them; body axes) over the run (generic path); "
                                    "FILE.bdf (.dat, .nas): as Nastran transient loads (DLOAD 1: TLOAD1, TABLED1, "
                                    "FORCE/MOMENT in the FE model's basic axes)"},
      {"--set NAME=VALUE", "a run-time parameter of the model (repeatable; not recompiled: the simulator "
                           "takes the value; docs/model-format.md, Parameters)"},
      {"--equilibrium", "first move the positions to static equilibrium (forces at zero velocity, "
                        "Newton on the constrained statics); the given velocities are kept. Reports "
                        "the iterations and residuals; no equilibrium stops the run"},
      SIM_OPTIONS,
      {"--quiet", "print nothing but errors"}}},
    {"bench", "mbcc bench M.yaml [--scene S] [--csv FILE] [--reps N] [--paths a,b,...] [OPTIONS]",
     "time every solution path of a model against SUNDIALS IDA",
     "Compiles a benchmark with every path (generated+ldl, generated+klu, generated+dense, "
     "generic+klu, generic+dense, ida, ida+klu) and prints the CPU time of each and its error against a "
     "tight reference.",
     {{"--scene S", "apply scene S of the model file"},
      {"--csv FILE", "also write the table as CSV"},
      {"--reps N", "repetitions; the fastest counts"},
      {"--paths a,b,...", "only these paths"},
      {"--integrator rk4|dopri5", "the integrator of the non-IDA paths"},
      {"--end T", "end time, s"}, {"--rtol R, --atol A", "tolerances"},
      {"--ida-rtol R", "the tolerance of IDA"},
      {"--quiet", "print the table only"}}},
    {"modes", "mbcc modes M.yaml --body NAME [--scene S] [--shapes FILE.csv] [--write-modal FILE.modal.yaml] [--suggest]",
     "the natural frequencies and mode shapes of one flexible body",
     "Computes the body's modes as the model selects them (constrained normal modes, or "
     "Craig-Bampton with interface nodes) and prints the frequencies.",
     {{"--body NAME", "the flexible body"},
      {"--scene S", "apply scene S of the model file"},
      {"--shapes FILE.csv", "write the mode shapes at every node"},
      {"--write-modal FILE", "write the modes as a modal file (docs/modal-file.md)"},
      {"--suggest", "rank the modes by the loads of a rigid pre-run (the body rigid, the joints "
                    "and force elements on its nodes) and suggest a mode list"}}},
    {"plot", "mbcc plot A.csv [B.csv ...] [-o OUT.png] [--columns a,b+c,...] [--gnuplot FILE]",
     "plot results with gnuplot, one panel per column against time",
     "Every column (or those of --columns) gets a panel; a panel shows the column of every CSV file "
     "given (overlay of runs), and a+b draws columns a and b in one panel. Eight panels make a page: "
     "more pages go to OUT-2.png, OUT-3.png, ... A column whose variation is round-off (below 1e-12 "
     "of its own or of the largest column's scale) is drawn as exactly zero and labelled so. Axis "
     "units come from FILE.csv.units when it exists. An unknown column is an error that lists the "
     "known ones.",
     {{"-o OUT.png", "the plot (default: the first CSV with .png)"},
      {"--columns a,b+c,...", "the columns, in order; + joins columns in one panel (default: all but the pose columns body.*)"},
      {"--gnuplot FILE", "keep the gnuplot script in FILE (to restyle the plot)"},
      {"--quiet", "print nothing but errors"}}},
    {"animate", "mbcc animate results.csv [-m M.yaml] [--scene S] [-o out.html] [--scale S] [--quiet]",
     "a self-contained HTML page that plays a result's motion in the browser",
     "The CSV must hold the pose columns (body.NAME.r, .p, .w<j>) that mbcc run --animate adds. "
     "With the model, rigid bodies are drawn from their joint and marker points (or their shape) "
     "and flexible bodies deformed from their modal coordinates. See docs/animation.md.",
     {{"-m M.yaml", "the model, for the geometry"},
      {"--scene S", "apply scene S of the model file"},
      {"-o out.html", "the page (default: the CSV with .html)"},
      {"--scale S", "multiplies the drawn deformation of flexible bodies"},
      {"--quiet", "print nothing but errors"}}},
    {"trade", "mbcc trade M.yaml [--scene S] [--outputs a,b,...] [--max-error E] [OPTIONS]",
     "the speed/accuracy trade-off of a model's modelling and solver choices",
     "Sweeps modal truncation, coupling, joints, precision, integrator settings and solvers, runs each "
     "variant, and measures its CPU time and its error against a tight reference, over the outputs "
     "that vary: constants and conserved quantities (variation at round-off) are left out by default "
     "and listed. See docs/trade.md.",
     {{"--outputs a,b,...", "the columns to compare (default: those that vary)"},
      {"--max-error E[,E2]", "the error budget(s); the fastest run within each is reported"},
      {"--csv FILE", "write every run as CSV"},
      {"--plot FILE.png|none", "the Pareto plot"},
      {"--reps N", "timing repetitions (default 3)"},
      {"--end T, --output-step H", "the simulated interval and output step"},
      {"--integrators rk4@H,dopri5@R,...", "integrator settings to sweep"},
      {"--modes all,N,FHz,...", "modal truncations"},
      {"--couplings full,partial,constant,rigid", "flexible coupling variants"},
      {"--joints direct,virtual", "joint lowering variants"},
      {"--solvers ldl,klu,dense", "solvers"}, {"--reals double,float", "precisions"},
      {"--ref-rtol R", "the reference's tolerance (default 1e-10)"},
      {"--workdir DIR", "keep the runs' files in DIR"},
      {"--quiet", "print the summary only"}}},
    {"sweep", "mbcc sweep M.yaml --vary NAME=SPEC ... [--design full|lhs|oat] [--samples N] [--csv FILE] [OPTIONS]",
     "run a design of experiments over a model's run-time parameters",
     "Compiles the model once, writes one job per variant (the simulator with --set NAME=VALUE) to "
     "DIR/jobs.txt and runs them with GNU parallel, locally or on other machines (--sshlogin, which "
     "must share the file system), or writes a Slurm job array over the same list (--slurm). Then "
     "merges the runs into one CSV: the run number, the parameters, the status and, per run, the "
     "chosen statistics of its output columns (default: the maximum and minimum of each). A failed "
     "run is marked failed with its reason on stderr, and the exit status is then 1. See "
     "docs/sweeps.md.",
     {{"--vary NAME=v1,v2,...", "a run-time parameter's values; NAME=lo:hi:n for n evenly spaced "
                                "(lo:hi:n:log: logarithmically), NAME=lo:hi a range (lhs)"},
      {"--design full|lhs|oat", "full factorial (default), Latin hypercube of --samples N runs, or one "
                                "at a time from the middle values"},
      {"--samples N", "lhs: the number of runs"}, {"--seed N", "lhs: the random seed (default 1)"},
      {"--metric COLUMN:STAT", "a result per run; STAT max, min, maxabs, final, mean or rms (repeatable)"},
      {"--set NAME=VALUE", "a run-time parameter fixed for every run"},
      {"--dir DIR", "the jobs, the design and the runs' files (default: sweeps/NAME/)"},
      {"--csv FILE", "the merged results (default: DIR/sweep.csv)"},
      {"--jobs N, -j N", "runs at once (default: one per core)"},
      {"--sshlogin LOGINS", "GNU parallel's --sshlogin: run on these machines"},
      {"--slurm FILE", "write a Slurm job-array script instead of running"},
      {"--merge DIR", "merge the runs of DIR again (e.g. after the Slurm array)"},
      {"--scene S", "apply scene S of the model file"},
      {"--end T, --rtol R, ...", "the simulation options of mbcc run"},
      {"--quiet", "print nothing but errors"}}},
    {"help", "mbcc help [CMD]",
     "this help; mbcc CMD --help is the same as mbcc help CMD",
     "mbcc --version prints the version; mbcc help --man prints the man page.",
     {{0, 0}}},
};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

static const char overview[] =
    "mbcc compiles a multibody model (YAML: rigid and flexible bodies, joints, drivers, forces, "
    "outputs) into specialized C code with a fixed sparse pattern and its own LDL^T, and runs it. "
    "The model format is described in docs/model-format.md.";

void help_usage(FILE *f) {
  for (int c = 0; c < NCOMMANDS; c++) fprintf(f, "%s %s\n", c ? "      " : "usage:", commands[c].synopsis);
}

/* text wrapped at 78 columns, every line indented by 'indent' */
static void wrap(FILE *f, const char *text, int indent, int first_col) {
  int col = first_col;
  const char *p = text;
  while (*p) {
    size_t len = strcspn(p, " ");
    if (col > indent && col + 1 + (int)len > 78) {
      fprintf(f, "\n%*s", indent, "");
      col = indent;
    } else if (col > indent) {
      fputc(' ', f);
      col++;
    } else if (col < indent) {
      fprintf(f, "%*s", indent - col, "");
      col = indent;
    }
    fwrite(p, 1, len, f);
    col += (int)len;
    p += len;
    while (*p == ' ') p++;
  }
  fputc('\n', f);
}

int help_print(FILE *f, const char *cmd) {
  if (!cmd) {
    fprintf(f, "mbcc %s: the multibody code-generating compiler\n\n", MBCC_VERSION);
    help_usage(f);
    fputc('\n', f);
    for (int c = 0; c < NCOMMANDS; c++) fprintf(f, "  %-8s %s\n", commands[c].name, commands[c].summary);
    fputc('\n', f);
    wrap(f, overview, 0, 0);
    fprintf(f, "\nmbcc help CMD (or mbcc CMD --help) shows a command's options.\n");
    return 0;
  }
  for (int c = 0; c < NCOMMANDS; c++) {
    const help_command *h = &commands[c];
    if (strcmp(h->name, cmd)) continue;
    fprintf(f, "usage: %s\n\n", h->synopsis);
    wrap(f, h->summary, 0, 0);
    fputc('\n', f);
    wrap(f, h->description, 0, 0);
    if (h->opts[0].opt) fprintf(f, "\noptions:\n");
    for (int k = 0; h->opts[k].opt; k++) {
      fprintf(f, "  %s", h->opts[k].opt);
      int col = 2 + (int)strlen(h->opts[k].opt);
      if (col > 30) { fputc('\n', f); col = 0; }
      wrap(f, h->opts[k].text, 32, col);
    }
    return 0;
  }
  return -1;
}

/* troff: a leading dot or quote, and backslashes, must not be read as requests */
static void roff(FILE *f, const char *s) {
  if (*s == '.' || *s == '\'') fputs("\\&", f);
  for (; *s; s++) {
    if (*s == '\\') fputs("\\e", f);
    else if (*s == '-') fputs("\\-", f);
    else fputc(*s, f);
  }
}

void help_man(FILE *f) {
  fprintf(f, ".\\\" generated by `mbcc help --man` (make man) from compiler/help.c: do not edit\n");
  fprintf(f, ".TH MBCC 1 \"\" \"mbcc %s\" \"User Commands\"\n", MBCC_VERSION);
  fprintf(f, ".SH NAME\nmbcc \\- the multibody code\\-generating compiler\n.SH SYNOPSIS\n.nf\n");
  for (int c = 0; c < NCOMMANDS; c++) { roff(f, commands[c].synopsis); fputc('\n', f); }
  fprintf(f, ".fi\n.SH DESCRIPTION\n");
  roff(f, overview);
  fprintf(f, "\n.SH COMMANDS\n");
  for (int c = 0; c < NCOMMANDS; c++) {
    const help_command *h = &commands[c];
    fprintf(f, ".SS %s\n", h->name);
    roff(f, h->summary);
    fprintf(f, ".\n.PP\n");
    roff(f, h->description);
    fputc('\n', f);
    for (int k = 0; h->opts[k].opt; k++) {
      fprintf(f, ".TP\n.B ");
      roff(f, h->opts[k].opt);
      fputc('\n', f);
      roff(f, h->opts[k].text);
      fputc('\n', f);
    }
  }
  fprintf(f, ".SH EXIT STATUS\n0 on success; 1 when a simulation fails; 2 for bad input "
             "(reported as FILE:LINE:COL: error: ...) or a failed tool.\n");
  fprintf(f, ".SH FILES\n.TP\n.B generated/NAME/\nthe emitted code of mbcc run and mbcc compile, in the current directory\n"
             ".TP\n.B results/NAME.csv, NAME.csv.units, NAME.png\nthe results of mbcc run, in the current directory (or --results DIR)\n");
  fprintf(f, ".SH SEE ALSO\n.BR gnuplot (1),\n.BR pkg\\-config (1);\nshare/doc/mbcc/model\\-format.md\n");
}
