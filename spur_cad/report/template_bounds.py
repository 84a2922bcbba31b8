"""The bounds a report template renders within (issue 49): a shop's template is input, not code, and may be
hostile. Jinja2's sandbox already keeps it from Python's internals; this module keeps it from exhausting the
machine. One principle: every value a template makes is measured where it is made, so that no single operation
(each one a C call that nothing can interrupt) works on more than a bounded size, and the template's loops,
calls and output are counted against a deadline and a budget.

Where values are made, and the Jinja2 mechanism that sees it:

- operators (`* ** + % ...`): the sandbox's `intercepted_binops` / `call_binop`, which estimates the result's
  size before computing it (a string times 10^10 is refused before it is made);
- calls of macros, `caller()`, `loop()` and methods: the sandbox's `call` (recursion depth, deadline, the
  result's size); only the methods of text, lists and dicts that cannot grow a value are callable on them
  (`is_safe_attribute`), and `str.format` is not callable at all;
- filters: the environment's filter table holds a chosen set, each wrapped to check its arguments and result;
  filters whose output can be far larger than their input (`indent`, `wordwrap`, `pprint`, `urlize`) are left out;
- list, tuple and dict literals, `~` concatenations and `for` loops: the template's syntax tree, parsed by Jinja2,
  has each of them wrapped in a call to this environment (a `NodeTransformer`) before it is compiled; every loop
  pass is counted and checks the deadline;
- captured output (macros, `{% set %}` blocks, `{% filter %}` blocks): the environment's `concat`;
- printed values: the environment's `finalize`; the page itself is streamed (`Template.generate`) and counted.

A value's size is its expanded size: characters of text, digits of numbers, elements of lists, tuples and
dicts counted through shared references (a list of ten references to one list of ten strings counts 100
strings), so that printing or comparing it is bounded too. `namespace` and `lipsum` are not given to templates
(a namespace carries values from one loop pass to the next; lipsum makes text of any length).
"""

from __future__ import annotations

import functools
import inspect
import math
import re
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import jinja2
from jinja2 import nodes
from jinja2.filters import FILTERS
from jinja2.runtime import markup_join, str_join
from jinja2.sandbox import MAX_RANGE, ImmutableSandboxedEnvironment
from jinja2.utils import Cycler, Joiner, pass_eval_context
from jinja2.visitor import NodeTransformer
from markupsafe import Markup


@dataclass(frozen=True)
class TemplateLimits:
    """What one rendering of a report template may take. spur_cad's own template, on the reference job: 0.02 s,
    0.55 MB of page, 2.2 M characters made, 392 loop passes, calls 2 deep (docs/report.md)."""

    time_s: float = 10.0
    """Wall-clock time of the rendering."""
    output_bytes: int = 32 * 1024 * 1024
    """The page's size (UTF-8)."""
    value_size: int = 4 * 1024 * 1024
    """One value's expanded size: characters, digits, elements."""
    made_size: int = 64 * 1024 * 1024
    """All values made while rendering (printed, captured, computed), summed: bounds memory and work."""
    loop_passes: int = 1_000_000
    """Passes of all the template's loops together."""
    range_items: int = MAX_RANGE
    """Items of one `range()` (Jinja2's own sandbox bound, 100,000)."""
    call_depth: int = 50
    """Nesting of macro, caller and loop calls (recursion)."""
    int_digits: int = 4300
    """Decimal digits of a whole number made by an operator or a filter, and of the operands of `%`, `//` and `/`
    (Python's own limit for converting one to text)."""


class TemplateBoundError(jinja2.TemplateRuntimeError):
    """A template passed one of its TemplateLimits (Jinja2 adds the template's line to the traceback)."""


class TemplateTooDeepError(ValueError):
    """A template nested more deeply than Jinja2's parser or Python's compiler takes (blocks, loops, conditions
    or brackets inside one another); `line` is the template's line where it is known."""

    def __init__(self, line: int | None) -> None:
        super().__init__("the template nests too deeply (loops, blocks, conditions or brackets inside one another)")
        self.line = line


SAFE_METHODS = frozenset({
    "upper", "lower", "title", "capitalize", "casefold", "swapcase", "strip", "lstrip", "rstrip", "split", "rsplit",
    "splitlines", "partition", "rpartition", "removeprefix", "removesuffix", "startswith", "endswith", "count",
    "find", "rfind", "index", "rindex", "isdigit", "isalpha", "isalnum", "isspace", "isupper", "islower",
    "items", "keys", "values", "get", "tolist", "item", "min", "max", "mean", "sum", "any", "all",
})
"""The methods a template may call on text, numbers, lists, dicts and numpy values: none can make a value much
larger than the one it is called on (`center`, `zfill`, `join`, `replace`, `format`, `to_bytes`, numpy's `repeat`
could)."""

_BUILTIN_TYPES = (str, bytes, int, float, complex, list, tuple, dict, set, frozenset, range)

LEFT_OUT_FILTERS = frozenset({"indent", "wordwrap", "pprint", "urlize", "random", "striptags"})
"""Jinja2 filters a report template cannot use: their output can be far larger than their input, or they are
not needed for a sheet (random)."""

_WIDE_FORMAT = re.compile(r"%(\([^)]*\))?[-#0 +]*(\*|[0-9]{4,}|\.\*|\.[0-9]{4,})")
"""A printf-style conversion with a `*` or a width or precision of 4 digits or more."""

_CONVERSION = re.compile(r"%(?:\(([^)]*)\))?[-#0 +]*([0-9]*)(?:\.([0-9]*))?[hlL]?(.)", re.DOTALL)
"""One printf-style conversion: its mapping key, width, precision and type (`%%` has type '%')."""

_NUMBER_TEXT = 330
"""At most the characters a float prints as with %f, %e or %g before its precision (1e308 has 309 digits)."""

_LOG10_2 = math.log10(2)


def whole_number_digits(number: int) -> int:
    """At most the decimal digits of `number` (from its bits, without converting it)."""
    return int(abs(number).bit_length() * _LOG10_2) + 1


def _scalar_size(item: Any) -> int | None:
    """The printed size of text and numbers (None for anything else): whole numbers by their bits, not by
    converting them."""
    if isinstance(item, (str, bytes)):
        return len(item)
    if item is None or isinstance(item, bool):
        return 5
    if isinstance(item, int):
        return whole_number_digits(item) + 1
    if isinstance(item, (float, complex)):
        return 24
    return None


def _numeric(value: Any) -> bool:
    return isinstance(value, (int, float, complex)) and not isinstance(value, bool)


class BoundedSandbox(ImmutableSandboxedEnvironment):
    """Jinja2's immutable sandbox that renders a template within `limits` (see the module's docstring). One
    environment renders one template at a time: `bounded_render` starts its clock and budget."""

    intercepted_binops = frozenset({"+", "-", "*", "/", "//", "%", "**"})

    def __init__(self, limits: TemplateLimits = TemplateLimits()) -> None:
        super().__init__(autoescape=True, undefined=jinja2.StrictUndefined, keep_trailing_newline=True,
                         optimized=False, finalize=self._printed)
        self.limits = limits
        self.globals = {"range": self._range, "dict": dict, "cycler": Cycler, "joiner": Joiner}
        self.filters = {name: self._bounded_filter(name, function) for name, function in FILTERS.items()
                        if name not in LEFT_OUT_FILTERS}
        self._deadline: float | None = None  # None: not rendering (compiling)
        self._made = 0
        self._passes = 0
        self._depth = 0
        self._opaque_sizes: dict[int, tuple[object, int]] = {}  # id -> (the object, kept alive; its repr's length)

    # --- compiling -------------------------------------------------------------------------------------------

    def bounded_template(self, text: str) -> jinja2.Template:
        """`text` parsed, its loops, literals and concatenations wrapped (_Counted), compiled."""
        try:
            tree = _Counted(self).visit(self.parse(text))
        except (RecursionError, MemoryError):  # Jinja2's parser nests a call for each level
            raise TemplateTooDeepError(None) from None
        try:
            return self.from_string(tree)
        except (RecursionError, MemoryError):  # Jinja2's code generator, or Python's parser
            raise TemplateTooDeepError(None) from None
        except SyntaxError as exc:  # 'too many levels of indentation', 'too many statically nested blocks'
            raise TemplateTooDeepError(self._template_line(tree, exc.lineno)) from None

    def _template_line(self, tree: nodes.Template, code_line: int | None) -> int | None:
        """The template's line that the generated Python's `code_line` was made from (Jinja2's debug_info)."""
        if code_line is None:
            return None
        try:
            source = self.compile(tree, raw=True)
        except (RecursionError, MemoryError):
            return None
        found = re.search(r"^debug_info = '([0-9=&]*)'", source, re.MULTILINE)
        pairs = [tuple(map(int, pair.split("="))) for pair in found.group(1).split("&") if pair] if found else []
        lines = [template_line for template_line, line in pairs if line <= code_line]
        return lines[-1] if lines else None

    # --- rendering -------------------------------------------------------------------------------------------

    def bounded_render(self, template: jinja2.Template, context: dict) -> str:
        """The page, streamed and counted; a TemplateBoundError when a limit is passed."""
        self._deadline = time.monotonic() + self.limits.time_s
        self._made = self._passes = self._depth = 0
        self._opaque_sizes = {}
        try:
            chunks, size = [], 0
            for chunk in template.generate(context):
                size += len(chunk)  # characters: at least a quarter of the bytes; the bytes are checked below
                if size > self.limits.output_bytes:
                    raise TemplateBoundError(f"the page passed {self.limits.output_bytes:,} bytes")
                self._check_time()
                chunks.append(chunk)
            page = "".join(chunks)
            if len(page.encode("utf-8")) > self.limits.output_bytes:
                raise TemplateBoundError(f"the page passed {self.limits.output_bytes:,} bytes")
            return page
        finally:
            self._deadline = None
            self._opaque_sizes = {}

    def _check_time(self) -> None:
        if self._deadline is not None and time.monotonic() > self._deadline:
            raise TemplateBoundError(f"rendering took longer than {self.limits.time_s:g} s")

    def size_of(self, value: Any) -> int:
        """`value`'s expanded size (characters, digits, elements through shared references), counted only up to
        just past limits.value_size."""
        limit = self.limits.value_size
        seen: dict[int, int] = {}  # containers measured in this walk (alive: `value` holds them)

        def walk(item: Any, depth: int) -> int:
            scalar = _scalar_size(item)
            if scalar is not None:
                return scalar
            key = id(item)
            if key in seen:
                return seen[key]
            if depth > 200:
                raise TemplateBoundError("a value is nested more than 200 levels deep")
            if isinstance(item, (Mapping, list, tuple, set, frozenset)):
                pairs = item.items() if isinstance(item, Mapping) else ((element, None) for element in item)
                total = 2
                for first, second in pairs:  # a dict's name and value; an element and nothing
                    total += walk(first, depth + 1) + (walk(second, depth + 1) if second is not None else 0) + 2
                    if total > limit:
                        break
            else:
                total = self._opaque_size(item)
            seen[key] = total
            return total

        return walk(value, 0)

    def _opaque_size(self, item: Any) -> int:
        """The length of an object's repr (what printing it inside a list shows), once per object and rendering."""
        key = id(item)
        if key not in self._opaque_sizes:
            self._opaque_sizes[key] = (item, len(repr(item)))  # the object is kept: its id stays its own
        return self._opaque_sizes[key][1]

    def _within(self, value: Any, what: str) -> int:
        """`value`'s size, checked against the value limit (0 while compiling: constants are bounded by the
        template's own size). For what an operation is given (loop items, call arguments, attribute values,
        filter inputs), before the operation works on it."""
        if self._deadline is None:
            return 0
        self._check_time()
        size = self.size_of(value)
        if size > self.limits.value_size:
            raise TemplateBoundError(f"{what} larger than {self.limits.value_size:,} characters or elements")
        return size

    def _check_digits(self, number: Any, what: str) -> None:
        """A whole number of at most limits.int_digits digits."""
        if isinstance(number, int) and not isinstance(number, bool) \
                and whole_number_digits(number) > self.limits.int_digits:
            raise TemplateBoundError(f"{what} has more than {self.limits.int_digits:,} digits")

    def _checked(self, value: Any, what: str = "a value") -> Any:
        """`value` when its size is within the value limit and the budget of values made; counts it as made."""
        if self._deadline is None:  # compiling: constants are bounded by the template's own size
            return value
        self._check_digits(value, what)
        self._made += self._within(value, what)
        if self._made > self.limits.made_size:
            raise TemplateBoundError(f"the template made more than {self.limits.made_size:,} characters or "
                                     "elements of values in all")
        return value

    def _printed(self, value: Any) -> Any:
        """finalize: every printed value is checked before Jinja2 turns it into text."""
        return self._checked(value, "a printed value")

    def concat(self, parts: Iterable[str]) -> str:  # type: ignore[override]
        """Captured output (macros, set and filter blocks) joined within the value limit."""
        parts = list(parts)
        size = sum(len(part) for part in parts)
        if size > self.limits.value_size:
            raise TemplateBoundError(f"captured output (a macro's or a block's) larger than "
                                     f"{self.limits.value_size:,} characters")
        return self._checked("".join(parts), "captured output")

    def _range(self, *args: int) -> range:
        """range() of at most limits.range_items items."""
        items = range(*args)
        if len(items) > self.limits.range_items:
            raise TemplateBoundError(f"a range of {len(items):,} items; at most {self.limits.range_items:,}")
        return items

    def loop_passes(self, iterable: Iterable) -> Iterator:
        """`iterable`'s items, each pass of the loop counted and the deadline checked."""
        for item in iterable:
            self._passes += 1
            if self._passes > self.limits.loop_passes:
                raise TemplateBoundError(f"the template's loops made more than {self.limits.loop_passes:,} "
                                         "passes in all")
            self._within(item, "a loop's item")
            yield item

    def literal(self, value: Any) -> Any:
        """A list, tuple or dict written in the template, checked."""
        return self._checked(value, "a list, tuple or dict")

    @pass_eval_context
    def joined(self, eval_ctx: Any, *parts: Any) -> str:
        """`a ~ b ~ c`: the parts checked together before they are turned into text and joined."""
        self._checked(parts, "a ~ concatenation")
        return (markup_join if eval_ctx.autoescape else str_join)(parts)

    # --- the sandbox's hooks ---------------------------------------------------------------------------------

    def getattr(self, obj: Any, attribute: str) -> Any:
        """`obj.attribute` as the sandbox gives it, text and containers checked against the value limit."""
        return self._attribute_value(super().getattr(obj, attribute), attribute)

    def getitem(self, obj: Any, argument: Any) -> Any:
        """`obj[argument]` as the sandbox gives it, text and containers checked against the value limit."""
        return self._attribute_value(super().getitem(obj, argument), argument)

    def _attribute_value(self, value: Any, name: Any) -> Any:
        """`value` (an attribute's or an item's) when it is not text or a container larger than the value limit
        (other objects are measured when they are printed or given to a filter)."""
        if isinstance(value, (str, bytes, list, tuple, dict, set, frozenset)):
            self._within(value, f"the value of {str(name)[:40]!r}")
        return value

    def is_safe_attribute(self, obj: Any, attr: str, value: Any) -> bool:
        """The sandbox's rule, and on text, numbers, containers and numpy values only the SAFE_METHODS."""
        if not super().is_safe_attribute(obj, attr, value):
            return False
        restricted = isinstance(obj, _BUILTIN_TYPES) or type(obj).__module__.split(".")[0] == "numpy"
        return not (restricted and callable(value) and attr not in SAFE_METHODS)

    def wrap_str_format(self, value: Any) -> None:
        """str.format is not offered (its widths make text of any length): is_safe_attribute refuses it."""
        return None

    def call_binop(self, context: jinja2.runtime.Context, operator_name: str, left: Any, right: Any) -> Any:
        """An operator whose result's size is estimated first where it can be large (`*`, `**`, `%`), and whose
        whole-number operands have at most limits.int_digits digits where its time grows faster than their size
        (`%`, `//`, `/`)."""
        self._check_time()
        if operator_name == "*":
            self._check_product(left, right)
        elif operator_name == "**":
            self._check_power(left, right)
        elif operator_name == "%" and isinstance(left, str):
            self.check_printf(left, right)
        if operator_name in ("%", "//", "/"):
            self._check_digits(left, f"the left operand of {operator_name}")
            self._check_digits(right, f"the right operand of {operator_name}")
        return self._checked(super().call_binop(context, operator_name, left, right), "an operator's result")

    def _check_power(self, base: Any, exponent: Any) -> None:
        """`base ** exponent` of whole numbers: at most limits.int_digits digits (exponent * log10 |base|)."""
        if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1 \
                and exponent * math.log10(abs(base)) > self.limits.int_digits:
            raise TemplateBoundError(f"a power with more than {self.limits.int_digits:,} digits")

    def _check_product(self, left: Any, right: Any) -> None:
        """`left * right`: a repeated sequence or a product of whole numbers within its limit."""
        if isinstance(left, int) and isinstance(right, int):
            if (abs(left).bit_length() + abs(right).bit_length()) * _LOG10_2 > self.limits.int_digits:
                raise TemplateBoundError(f"a product with more than {self.limits.int_digits:,} digits")
            return
        count, sequence = (left, right) if isinstance(left, int) else (right, left)
        if isinstance(count, int) and isinstance(sequence, (str, list, tuple)) and count > 0 \
                and count * self.size_of(sequence) > self.limits.value_size:
            raise TemplateBoundError(f"a sequence repeated {count:,} times, larger than "
                                     f"{self.limits.value_size:,} characters or elements")

    def call(__self, __context: jinja2.runtime.Context, __obj: Any, *args: Any,  # noqa: N805 - Jinja2's own
             **kwargs: Any) -> Any:
        """A call from the template: its arguments within the value limit, nested at most limits.call_depth
        deep, its result checked."""
        __self._check_time()
        if getattr(__obj, "__func__", None) not in _SELF_CHECKED:  # those check what they are given themselves
            __self._within((args, kwargs), "a call's arguments")
        if __self._depth >= __self.limits.call_depth:
            raise TemplateBoundError(f"calls nested more than {__self.limits.call_depth} deep (a recursive macro?)")
        __self._depth += 1
        try:
            result = super().call(__context, __obj, *args, **kwargs)
        finally:
            __self._depth -= 1
        if isinstance(result, Iterator) or getattr(__obj, "__func__", None) in _SELF_CHECKED:
            return result  # checked by the wrapper itself, or as it is iterated
        return __self._checked(result, "a call's result")

    def _bounded_filter(self, name: str, function: Callable) -> Callable:
        """`function` (a Jinja2 filter) with its input and arguments within the value limit, its whole-number
        arguments at most limits.range_items, its own guard (FILTER_GUARDS) and its result checked (a whole
        number: at most limits.int_digits digits)."""
        signature = inspect.signature(function)
        guard = FILTER_GUARDS.get(name)
        passes = getattr(function, "jinja_pass_arg", None) is not None
        # an async variant (slice, ...) is marked pass_eval_context, but its signature is the plain function's
        signed = not passes or next(iter(signature.parameters), "") in ("eval_ctx", "context", "environment")

        @functools.wraps(function)  # keeps Jinja2's pass_eval_context / pass_environment marks
        def bounded(*args: Any, **kwargs: Any) -> Any:
            given = args[1 if passes else 0:]
            self._within((given, kwargs), f"the {name} filter's input and arguments")
            options = list(given[1:]) + list(kwargs.values())
            for option in options:
                if isinstance(option, int) and not isinstance(option, bool) \
                        and abs(option) > self.limits.range_items:
                    raise TemplateBoundError(f"the {name} filter was given {option:,}; numbers given to filters "
                                             f"are at most {self.limits.range_items:,}")
            if guard is not None:
                guard(self, signature.bind(*(args if signed else args[1:]), **kwargs).arguments)
            result = function(*args, **kwargs)
            return result if isinstance(result, Iterator) else self._checked(result, f"the {name} filter's result")

        return bounded


    def check_printf(self, text: str, values: Any) -> None:
        """`text % values` (the `%` operator, the format filter) without `*` or wide conversions, its result's
        size estimated before it is made: the text plus, for each conversion, its argument's size (an argument
        named by a mapping key counted at each of its conversions), its width and precision; %r and %a as ten
        characters an element (escapes), arguments of Markup text six (HTML escapes)."""
        check_format(text)
        positional = values if isinstance(values, tuple) else (values,)
        escape = 6 if isinstance(text, Markup) else 1
        size, index = len(text), 0
        for match in _CONVERSION.finditer(text):
            key, width, precision, kind = match.groups()
            if kind == "%":
                continue
            if key is not None:
                value = values.get(key) if isinstance(values, Mapping) else None
            else:
                value = positional[index] if index < len(positional) else None
                index += 1
            content = self.size_of(value) * (10 if kind in "ra" else 1) * escape
            if _numeric(value):
                content += _NUMBER_TEXT
            size += max(int(width or 0), content + int(precision or 0))
            if size > self.limits.value_size:
                raise TemplateBoundError(f"a %-format whose result would be larger than "
                                         f"{self.limits.value_size:,} characters")


_SELF_CHECKED = (BoundedSandbox.loop_passes, BoundedSandbox.literal, BoundedSandbox.joined)
"""The environment's own functions that the rewritten template calls: they check what they return."""


def check_format(text: str) -> None:
    """printf-style formatting (`%` and the format filter) without `*` or widths and precisions of 4 digits."""
    if _WIDE_FORMAT.search(text):
        raise TemplateBoundError("a %-format with a '*' or a width or precision of 1000 or more")


def _guard_join(env: BoundedSandbox, arguments: dict) -> None:
    value, separator = arguments.get("value"), arguments.get("d", "")
    if isinstance(value, (list, tuple)) and len(value) * len(str(separator)) + env.size_of(value) \
            > env.limits.value_size:
        raise TemplateBoundError(f"the join filter would make more than {env.limits.value_size:,} characters")


def _guard_replace(env: BoundedSandbox, arguments: dict) -> None:
    text, new = str(arguments.get("s", "")), str(arguments.get("new", ""))
    if (len(text) + 1) * max(1, len(new)) > env.limits.value_size:
        raise TemplateBoundError(f"the replace filter could make more than {env.limits.value_size:,} characters")


def _guard_format(env: BoundedSandbox, arguments: dict) -> None:
    env.check_printf(str(arguments.get("value", "")), arguments.get("kwargs") or tuple(arguments.get("args", ())))


def _guard_int(env: BoundedSandbox, arguments: dict) -> None:
    value = arguments.get("value")
    if isinstance(value, str) and len(value) > 4 * env.limits.int_digits:  # the result is checked after
        raise TemplateBoundError(f"the int filter was given text of {len(value):,} characters; a whole number has "
                                 f"at most {env.limits.int_digits:,} digits")


def _guard_fill(env: BoundedSandbox, arguments: dict) -> None:
    """batch and slice: the fill value, repeated up to `linecount` times in a batch, once in each of `slices`."""
    count = arguments.get("linecount", arguments.get("slices", 0))
    fill = arguments.get("fill_with")
    if fill is not None and isinstance(count, int) and count * env.size_of(fill) > env.limits.value_size:
        raise TemplateBoundError(f"the fill value repeated {count:,} times, larger than "
                                 f"{env.limits.value_size:,} characters or elements")


def _guard_sum(env: BoundedSandbox, arguments: dict) -> None:
    if not _numeric(arguments.get("start", 0)):  # adding lists one by one takes time quadratic in their length
        raise TemplateBoundError("the sum filter adds numbers only")


FILTER_GUARDS: dict[str, Callable[[BoundedSandbox, dict], None]] = {
    "join": _guard_join, "replace": _guard_replace, "format": _guard_format, "sum": _guard_sum, "int": _guard_int,
    "batch": _guard_fill, "slice": _guard_fill}
"""Checks made before a filter whose output can be much larger than its input, or slower than linear."""


class _Counted(NodeTransformer):
    """The template's syntax tree with every loop's iterable, list, tuple and dict literal and `~` concatenation
    wrapped in a call of the environment's loop_passes, literal and joined."""

    def __init__(self, environment: BoundedSandbox) -> None:
        self.environment = environment

    def _call(self, name: str, args: list, lineno: int) -> nodes.Call:
        call = nodes.Call(nodes.EnvironmentAttribute(name), args, [], None, None)
        call.set_lineno(lineno)
        call.set_environment(self.environment)
        return call

    def visit_For(self, node: nodes.For) -> nodes.For:
        self.generic_visit(node)
        node.iter = self._call("loop_passes", [node.iter], node.lineno)
        return node

    def _literal(self, node: nodes.Expr) -> nodes.Expr:
        self.generic_visit(node)
        return node if getattr(node, "ctx", "load") != "load" else self._call("literal", [node], node.lineno)

    visit_List = visit_Tuple = visit_Dict = _literal

    def visit_Concat(self, node: nodes.Concat) -> nodes.Call:
        self.generic_visit(node)
        return self._call("joined", list(node.nodes), node.lineno)


