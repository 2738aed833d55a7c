"""scripts/long_functions.py: no function in native/ or addon/ is over 120 lines, and the scanner
really finds functions (C++ and Python), so an empty listing means short functions, not a blind
scanner."""

import importlib.util
import pathlib
import subprocess
import sys
import textwrap

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "long_functions.py"

spec = importlib.util.spec_from_file_location("long_functions", SCRIPT)
long_functions = importlib.util.module_from_spec(spec)
spec.loader.exec_module(long_functions)

# Functions still over the limit in code other sessions own (issue 36): each entry must go when
# its function is split, and the test fails if a listed one is no longer long, so the list only
# shrinks. Nothing else may be long.
PENDING = set()  # addon/core/api/decimate.py's decimate is a thin adapter over core/api/job.py now

SNIPPET = textwrap.dedent(r'''
    #include <vector>
    #define OPEN {
    namespace topstoc {
    namespace {
    // a comment with a brace {
    const char* kText = "a string with } and { and \" quote";
    const char* kRaw = R"x(raw ) " } { string)x";
    constexpr char kBrace = '{';
    constexpr long kBig = 1'000'000;
    int table[] = {1, 2, 3};
    struct Holder {
      int x_, y_;
      Holder(int a) : x_(a), y_{a} {
        x_ += 1;
      }
      int get() const { return x_; }
      bool operator()(int a) const {
        return a > 0;
      }
    };
    auto lambda_at_namespace = [](int v) {
      /* { */
      return v + 1;
    };
    }  // namespace

    template <typename T>
    T twice(T v) {
      if (v) {
        for (int i = 0; i < 2; ++i) {
          v += v;
        }
      }
      auto local = [&](int w) { return w; };
      return v;
    }

    int Holder_free() noexcept {
      return 0;
    }
    }  // namespace topstoc
    ''')


def test_scanner_finds_every_cpp_function_with_its_lines():
    found = long_functions.cpp_functions(SNIPPET)
    by_name = {name: (line, length) for line, name, length in found}
    lines = SNIPPET.split("\n")

    def line_of(text):
        return next(i + 1 for i, line in enumerate(lines) if text in line)

    assert by_name == {
        "Holder": (line_of("Holder(int a)"), 3),
        "get": (line_of("int get()"), 1),
        "operator()": (line_of("bool operator()"), 3),
        "lambda_at_namespace": (line_of("auto lambda_at_namespace"), 4),
        "twice": (line_of("T twice(T v)"), 9),
        "Holder_free": (line_of("int Holder_free()"), 3),
    }


def test_scanner_reports_a_long_function_and_exits_1(tmp_path):
    body = "\n".join(f"  x += {i};" for i in range(130))
    (tmp_path / "long.cpp").write_text(f"int Foo::long_one(int x) {{\n{body}\n  return x;\n}}\nint short_one() {{ return 1; }}\n")
    (tmp_path / "long.py").write_text("def long_py():\n" + "\n".join(f"    x = {i}" for i in range(125)) + "\n")
    run = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path)], capture_output=True, text=True)
    assert run.returncode == 1
    listed = sorted(line.split(" ", 1)[1] for line in run.stdout.splitlines())
    assert listed == ["Foo::long_one 133", "long_py 126"]


def test_python_functions_counted_from_def_to_last_line():
    source = "def f():\n    a = 1\n\n    return a\n\n\nclass C:\n    def m(self):\n        pass\n"
    assert long_functions.python_functions(source) == [(1, "f", 4), (8, "m", 2)]


def test_no_function_over_120_lines_in_native_or_addon():
    over = long_functions.long_functions([ROOT / "native", ROOT / "addon"], 120)
    listed = {(str(pathlib.Path(path).relative_to(ROOT)), name) for path, _, name, _ in over}
    assert listed - PENDING == set(), "\n".join(f"{p}:{line} {name} {n}" for p, line, name, n in over)
    assert PENDING - listed == set(), "split: remove from PENDING"
    # The scanner sees the whole tree: hundreds of functions.
    total = sum(len(long_functions.scan_file(str(p))) for p in long_functions.source_files([ROOT / "native"]))
    assert total > 500
