#!/usr/bin/env python3
"""Generate iplan's C++ message layer from the IDL files in idl/.

The IDL is the single source of truth for the wire format. From it this script
writes, into --out:

  include/iplan/msg/types.h   plain C++ structs (no vendor types), constants,
                              field reflection (FieldsOf<T>::Visit) and the
                              DDS type name of every message.
  type_table.cc               the run-time table of every type (create, destroy,
                              JSON), used by tools that pick a type by name.
  fastdds_types.cc            conversions to/from fastddsgen classes and their
                              type-support table (raw-vendor benchmark and
                              wire-compatibility test only).
  fastdds_plain_types.cc      the table of Fast DDS type supports that
                              serialise the plain types directly (the data path).
  cyclone_types.cc            conversions to/from idlc C structs and the
                              Cyclone type-support table.

Only the IDL subset the project uses is accepted: modules, @final structs,
constants in modules, fields of primitive, string, sequence<T> (unbounded),
fixed arrays T name[N] and other structs. Anything else is an error with the
file and line, so an unsupported construct never slips through silently.

Naming: IDL `pkg::msg::dds_::Name_` becomes C++ `iplan::msg::Name`; constants
of module `Name_Constants` become static members of `iplan::msg::Name`.
"""

import argparse
import os
import re
import sys

PRIMITIVES = {
    "double": "double",
    "float": "float",
    "boolean": "bool",
    "octet": "uint8_t",
    "char": "char",
    "short": "int16_t",
    "unsigned short": "uint16_t",
    "long": "int32_t",
    "unsigned long": "uint32_t",
    "long long": "int64_t",
    "unsigned long long": "uint64_t",
}


class IdlError(Exception):
    pass


class Field:
    def __init__(self, name, kind, elem, array_len, comment):
        self.name = name
        self.kind = kind          # "prim", "string", "struct"
        self.elem = elem          # primitive IDL name or struct scoped name
        self.seq = False
        self.array_len = array_len
        self.comment = comment


class Struct:
    def __init__(self, scope, name, file, line):
        self.scope = scope        # ["iplan_msgs", "msg", "dds_"]
        self.name = name          # "HumanSkeleton_"
        self.fields = []
        self.consts = []          # (cpp_type, name, value)
        self.file = file
        self.line = line
        self.doc = ""

    @property
    def idl_name(self):
        return "::".join(self.scope + [self.name])

    @property
    def cpp_name(self):
        return self.name[:-1] if self.name.endswith("_") else self.name

    @property
    def c_name(self):
        return "_".join(self.scope + [self.name])


def tokenize(text, path):
    """Yields (token, line, trailing_comment) tuples; keeps comments for docs."""
    tokens = []
    i, line, n = 0, 1, len(text)
    pending_comment = []
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif c.isspace():
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            pending_comment.append((line, text[i + 2:j].strip()))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i)
            if j < 0:
                raise IdlError(f"{path}:{line}: unterminated comment")
            line += text.count("\n", i, j)
            i = j + 2
        elif c == "#":
            j = text.find("\n", i)
            j = n if j < 0 else j
            tokens.append(("#" + text[i + 1:j].strip(), line))
            i = j
        elif c.isalnum() or c == "_" or c == "@":
            j = i + 1
            while j < n and (text[j].isalnum() or text[j] == "_"):
                j += 1
            tokens.append((text[i:j], line))
            i = j
        elif text.startswith("::", i):
            tokens.append(("::", line))
            i += 2
        elif c in "{};<>[]=,()-\"":
            tokens.append((c, line))
            i += 1
        else:
            raise IdlError(f"{path}:{line}: unexpected character {c!r}")
    comments = {}
    for ln, txt in pending_comment:
        comments.setdefault(ln, []).append(txt)
    return tokens, comments


class Parser:
    def __init__(self):
        self.structs = {}         # idl_name -> Struct
        self.order = []
        self.consts = {}          # "scope::Name_Constants" -> list
        self.parsed_files = set()

    def parse_file(self, path, include_dirs):
        path = os.path.abspath(path)
        if path in self.parsed_files:
            return
        self.parsed_files.add(path)
        with open(path) as f:
            text = f.read()
        toks, comments = tokenize(text, path)
        self.path = path
        self.comments = comments
        self.toks = toks
        self.pos = 0
        self.include_dirs = include_dirs
        self.scope = []
        self._parse_definitions(top=True)

    def _peek(self, k=0):
        if self.pos + k < len(self.toks):
            return self.toks[self.pos + k][0]
        return None

    def _line(self):
        if self.pos < len(self.toks):
            return self.toks[self.pos][1]
        return self.toks[-1][1] if self.toks else 0

    def _next(self):
        tok = self.toks[self.pos]
        self.pos += 1
        return tok[0]

    def _expect(self, t):
        got = self._next() if self.pos < len(self.toks) else "end of file"
        if got != t:
            raise IdlError(f"{self.path}:{self._line()}: expected {t!r}, got {got!r}")

    def _err(self, msg):
        raise IdlError(f"{self.path}:{self._line()}: {msg}")

    def _parse_definitions(self, top):
        while self.pos < len(self.toks):
            t = self._peek()
            if t.startswith("#"):
                self._next()
                m = re.match(r'#include\s+"([^"]+)"', t)
                if m:
                    saved = (self.path, self.comments, self.toks, self.pos, self.scope)
                    inc = None
                    for d in [os.path.dirname(saved[0])] + self.include_dirs:
                        cand = os.path.join(d, m.group(1))
                        if os.path.exists(cand):
                            inc = cand
                            break
                    if inc is None:
                        self._err(f"cannot find included file {m.group(1)}")
                    self.parse_file(inc, self.include_dirs)
                    (self.path, self.comments, self.toks, self.pos, self.scope) = saved
                continue
            if t == "}":
                if top:
                    self._err("unbalanced '}'")
                return
            if t == "module":
                self._next()
                name = self._next()
                self._expect("{")
                self.scope.append(name)
                self._parse_definitions(top=False)
                self._expect("}")
                self._expect(";")
                self.scope.pop()
            elif t == "const":
                self._parse_const()
            elif t.startswith("@") or t == "struct":
                self._parse_struct()
            else:
                self._err(f"unsupported construct {t!r}")

    def _parse_type(self):
        t = self._next()
        if t == "unsigned":
            t2 = self._next()
            if t2 == "long" and self._peek() == "long":
                self._next()
                return ("prim", "unsigned long long")
            return ("prim", "unsigned " + t2)
        if t == "long" and self._peek() == "long":
            self._next()
            return ("prim", "long long")
        if t in PRIMITIVES:
            return ("prim", t)
        if t == "string":
            if self._peek() == "<":
                self._err("bounded strings are not supported")
            return ("string", "string")
        # scoped name
        parts = [t]
        while self._peek() == "::":
            self._next()
            parts.append(self._next())
        name = "::".join(parts)
        if name not in self.structs:
            # relative to current scope
            rel = "::".join(self.scope + parts)
            if rel in self.structs:
                name = rel
            else:
                self._err(f"unknown type {name}")
        return ("struct", name)

    def _parse_struct(self):
        line = self._line()
        final = False
        while self._peek().startswith("@"):
            ann = self._next()
            if ann == "@final":
                final = True
            else:
                self._err(f"annotation {ann} not supported (every type must be @final)")
        if not final:
            self._err("every struct must be annotated @final (XCDR1 interop between vendors)")
        self._expect("struct")
        name = self._next()
        st = Struct(list(self.scope), name, self.path, line)
        doc = []
        for ln in range(line - 3, line):
            doc.extend(self.comments.get(ln, []))
        st.doc = " ".join(doc)
        self._expect("{")
        while self._peek() != "}":
            fline = self._line()
            if self._peek() == "sequence":
                self._next()
                self._expect("<")
                kind, elem = self._parse_type()
                if self._peek() == ",":
                    self._err("bounded sequences are not supported")
                self._expect(">")
                fname = self._next()
                f = Field(fname, kind, elem, None, None)
                f.seq = True
            else:
                kind, elem = self._parse_type()
                fname = self._next()
                arr = None
                if self._peek() == "[":
                    self._next()
                    arr = int(self._next())
                    self._expect("]")
                f = Field(fname, kind, elem, arr, None)
            f.comment = " ".join(self.comments.get(fline, []))
            self._expect(";")
            st.fields.append(f)
        self._expect("}")
        self._expect(";")
        if st.idl_name in self.structs:
            self._err(f"struct {st.idl_name} defined twice")
        self.structs[st.idl_name] = st
        self.order.append(st)

    def _parse_const(self):
        self._next()
        kind, t = self._parse_type()
        if kind != "prim":
            self._err("only primitive constants are supported")
        name = self._next()
        if name.startswith("_"):  # IDL escaped identifier (e.g. _INT8: INT8 is a keyword)
            name = name[1:]
        self._expect("=")
        val = self._next()
        if val == "-":
            val = "-" + self._next()
        self._expect(";")
        self.consts.setdefault("::".join(self.scope), []).append((PRIMITIVES[t], name, val))


def cpp_field_type(f):
    if f.kind == "prim":
        base = PRIMITIVES[f.elem]
    elif f.kind == "string":
        base = "std::string"
    else:
        base = cpp_struct_name(f.elem)
    if f.seq:
        return f"std::vector<{base}>"
    if f.array_len is not None:
        return f"std::array<{base}, {f.array_len}>"
    return base


_structs_by_idl = {}


def cpp_struct_name(idl_name):
    return _structs_by_idl[idl_name].cpp_name


def fast_name(st):
    return "::" + st.idl_name


def default_init(f):
    if f.seq or f.array_len is not None:
        return "{}"
    if f.kind == "prim":
        return "false" if f.elem == "boolean" else "0"
    return "{}"


HEADER_PREAMBLE = """// Generated by tools/codegen/gen_msgs.py from idl/*.idl. Do not edit.
//
// Plain C++ message types of iplan: what services see. No DDS vendor type
// appears here; the DDS layer converts to and from the vendor types.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace iplan::msg {

/// FieldsOf<T>::Visit(f, m...) calls f(name, m.field...) for every field of T
/// in IDL order, on one or several messages of type T at once.
template <class T>
struct FieldsOf;

/// TypeName<T>::kDds is the DDS type name of T on the wire.
template <class T>
struct TypeName;

/// True for every generated message type.
template <class T, class = void>
struct IsMessage : std::false_type {};
template <class T>
struct IsMessage<T, std::void_t<decltype(TypeName<T>::kDds)>> : std::true_type {};
template <class T>
inline constexpr bool kIsMessage = IsMessage<T>::value;

"""


def gen_header(structs, consts):
    out = [HEADER_PREAMBLE]
    names = set()
    for st in structs:
        if st.cpp_name in names:
            raise IdlError(f"{st.file}:{st.line}: C++ name {st.cpp_name} used twice")
        names.add(st.cpp_name)
    for st in structs:
        if st.doc:
            out.append(f"/// {st.doc}\n")
        out.append(f"/// Wire type: {st.idl_name}\n")
        out.append(f"struct {st.cpp_name} {{\n")
        cmod = "::".join(st.scope + [st.name + "Constants"])
        for ctype, cname, cval in consts.get(cmod, []):
            out.append(f"  static constexpr {ctype} {cname} = {cval};\n")
        for f in st.fields:
            c = f"  // {f.comment}" if f.comment else ""
            out.append(f"  {cpp_field_type(f)} {f.name}{{{'' if default_init(f) == '{}' else default_init(f)}}};{c}\n")
        out.append("};\n\n")
        out.append(f"template <>\nstruct TypeName<{st.cpp_name}> {{\n")
        out.append(f"  static constexpr const char* kDds = \"{st.idl_name}\";\n")
        out.append(f"  static constexpr const char* kCpp = \"{st.cpp_name}\";\n}};\n\n")
        out.append(f"template <>\nstruct FieldsOf<{st.cpp_name}> {{\n")
        out.append(f"  static constexpr int kCount = {len(st.fields)};\n")
        out.append("  template <class F, class... M>\n  static void Visit(F&& f, M&... m) {\n")
        for f in st.fields:
            out.append(f"    f(\"{f.name}\", m.{f.name}...);\n")
        out.append("  }\n};\n\n")
    out.append("}  // namespace iplan::msg\n")
    return "".join(out)


def gen_type_table(structs):
    out = ["// Generated by tools/codegen/gen_msgs.py. Do not edit.\n",
           "#include \"iplan/msg/type_table.h\"\n#include \"iplan/msg/json.h\"\n#include \"iplan/msg/json_schema.h\"\n#include \"iplan/msg/visit.h\"\n\n",
           "namespace iplan::msg {\nnamespace {\n",
           "template <class T>\nconstexpr TypeEntry MakeEntry() {\n",
           "  return TypeEntry{TypeName<T>::kDds, TypeName<T>::kCpp,\n",
           "                   [] { return static_cast<void*>(new T()); },\n",
           "                   [](void* p) { delete static_cast<T*>(p); },\n",
           "                   [](const void* p) { return ToJson(*static_cast<const T*>(p)); },\n",
           "                   [](const nlohmann::json& j, void* p) { FromJson(j, static_cast<T*>(p)); },\n",
           "                   [](void* p, uint64_t seed) { std::mt19937_64 rng(seed); FillRandom(*static_cast<T*>(p), rng); },\n",
           "                   [](const void* a, const void* b) { return FirstDifference(*static_cast<const T*>(a), *static_cast<const T*>(b)); },\n",
           "                   [] { return JsonSchema<T>(); }};\n}\n",
           "const TypeEntry kEntries[] = {\n"]
    for st in structs:
        out.append(f"    MakeEntry<{st.cpp_name}>(),\n")
    out.append("};\n}  // namespace\n\n")
    out.append("const std::vector<TypeEntry>& AllTypes() {\n")
    out.append("  static const std::vector<TypeEntry> kAll(std::begin(kEntries), std::end(kEntries));\n")
    out.append("  return kAll;\n}\n\n}  // namespace iplan::msg\n")
    return "".join(out)


def gen_fastdds(structs, idl_files):
    out = ["// Generated by tools/codegen/gen_msgs.py. Do not edit.\n",
           "// Conversions between iplan::msg types and fastddsgen classes.\n",
           "#include \"fastdds_convert.h\"\n\n"]
    for f in idl_files:
        base = os.path.splitext(os.path.basename(f))[0]
        out.append(f"#include \"{base}PubSubTypes.h\"\n")
    out.append("// The class definitions are compiled here, not in their own files, so\n"
               "// that their out-of-line field accessors inline into the conversions.\n")
    for f in idl_files:
        base = os.path.splitext(os.path.basename(f))[0]
        out.append(f"#include \"{base}.cxx\"\n")
    out.append("\nnamespace iplan::dds::fastdds_gen {\n\n")
    for st in structs:
        out.append(f"void ToVendor(const msg::{st.cpp_name}& p, {fast_name(st)}& v);\n")
        out.append(f"void FromVendor({fast_name(st)}& v, msg::{st.cpp_name}& p);\n")
    out.append("\n#include \"fastdds_convert_generic.inc\"\n\n")
    for st in structs:
        out.append(f"void ToVendor(const msg::{st.cpp_name}& p, {fast_name(st)}& v) {{\n")
        for f in st.fields:
            out.append(f"  ToVendorField(p.{f.name}, v.{f.name}());\n")
        out.append("}\n")
        out.append(f"void FromVendor({fast_name(st)}& v, msg::{st.cpp_name}& p) {{\n")
        for f in st.fields:
            out.append(f"  FromVendorField(v.{f.name}(), p.{f.name});\n")
        out.append("}\n\n")
    out.append("namespace {\n")
    out.append("template <class P, class V, class PS>\nFastTypeOps MakeOps() {\n"
               "  FastTypeOps ops;\n"
               "  ops.dds_name = msg::TypeName<P>::kDds;\n"
               "  ops.make_pubsub_type = [] { return static_cast<eprosima::fastdds::dds::TopicDataType*>(new PS()); };\n"
               "  ops.new_vendor = [] { return static_cast<void*>(new V()); };\n"
               "  ops.delete_vendor = [](void* v) { delete static_cast<V*>(v); };\n"
               "  ops.to_vendor = [](const void* p, void* v) { ToVendor(*static_cast<const P*>(p), *static_cast<V*>(v)); };\n"
               "  ops.from_vendor = [](void* v, void* p) { FromVendor(*static_cast<V*>(v), *static_cast<P*>(p)); };\n"
               "  return ops;\n}\n}  // namespace\n\n")
    out.append("const std::vector<FastTypeOps>& AllFastTypes() {\n  static const std::vector<FastTypeOps> kAll = {\n")
    for st in structs:
        out.append(f"      MakeOps<msg::{st.cpp_name}, {fast_name(st)}, {fast_name(st)}PubSubType>(),\n")
    out.append("  };\n  return kAll;\n}\n\n}  // namespace iplan::dds::fastdds_gen\n")
    return "".join(out)


def gen_fastdds_plain(structs):
    out = ["// Generated by tools/codegen/gen_msgs.py. Do not edit.\n",
           "// Fast DDS type supports over the plain types, one per message type.\n",
           "#include \"fastdds_plain_type.h\"\n\n",
           "namespace iplan::dds::fastdds_plain {\n\n",
           "const std::vector<PlainTypeEntry>& AllPlainTypes() {\n",
           "  static const std::vector<PlainTypeEntry> kAll = {\n"]
    for st in structs:
        out.append(f"      MakeEntry<msg::{st.cpp_name}>(),\n")
    out.append("  };\n  return kAll;\n}\n\n}  // namespace iplan::dds::fastdds_plain\n")
    return "".join(out)


def gen_cyclone(structs, idl_files):
    out = ["// Generated by tools/codegen/gen_msgs.py. Do not edit.\n",
           "// Conversions between iplan::msg types and idlc's C structs.\n",
           "#include \"cyclone_convert.h\"\n\n"]
    for f in idl_files:
        base = os.path.splitext(os.path.basename(f))[0]
        out.append(f"#include \"{base}.h\"\n")
    out.append("\nnamespace iplan::dds::cyclone_gen {\n\n")
    for st in structs:
        out.append(f"void ToVendor(const msg::{st.cpp_name}& p, {st.c_name}& v, Arena& a);\n")
        out.append(f"void FromVendor(const {st.c_name}& v, msg::{st.cpp_name}& p);\n")
    out.append("\n#include \"cyclone_convert_generic.inc\"\n\n")
    for st in structs:
        out.append(f"void ToVendor(const msg::{st.cpp_name}& p, {st.c_name}& v, Arena& a) {{\n")
        if not st.fields:
            out.append("  (void)p; (void)v; (void)a;\n")
        for f in st.fields:
            out.append(f"  ToVendorField(p.{f.name}, v.{f.name}, a);\n")
        out.append("}\n")
        out.append(f"void FromVendor(const {st.c_name}& v, msg::{st.cpp_name}& p) {{\n")
        for f in st.fields:
            out.append(f"  FromVendorField(v.{f.name}, p.{f.name});\n")
        out.append("}\n\n")
    out.append("namespace {\n")
    out.append("template <class P, class V>\nCycloneTypeOps MakeOps(const dds_topic_descriptor_t* desc) {\n"
               "  CycloneTypeOps ops;\n"
               "  ops.dds_name = msg::TypeName<P>::kDds;\n"
               "  ops.descriptor = desc;\n"
               "  ops.vendor_size = sizeof(V);\n"
               "  ops.to_vendor = [](const void* p, void* v, Arena& a) { ToVendor(*static_cast<const P*>(p), *static_cast<V*>(v), a); };\n"
               "  ops.from_vendor = [](const void* v, void* p) { FromVendor(*static_cast<const V*>(v), *static_cast<P*>(p)); };\n"
               "  return ops;\n}\n}  // namespace\n\n")
    out.append("const std::vector<CycloneTypeOps>& AllCycloneTypes() {\n  static const std::vector<CycloneTypeOps> kAll = {\n")
    for st in structs:
        out.append(f"      MakeOps<msg::{st.cpp_name}, {st.c_name}>(&{st.c_name}_desc),\n")
    out.append("  };\n  return kAll;\n}\n\n}  // namespace iplan::dds::cyclone_gen\n")
    return "".join(out)


def write_if_changed(path, content):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if os.path.exists(path):
        with open(path) as f:
            if f.read() == content:
                return
    with open(path, "w") as f:
        f.write(content)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("idl", nargs="+", help="IDL files")
    args = ap.parse_args()
    p = Parser()
    inc = sorted({os.path.dirname(os.path.abspath(f)) for f in args.idl})
    try:
        for f in args.idl:
            p.parse_file(f, inc)
        for st in p.order:
            _structs_by_idl[st.idl_name] = st
        write_if_changed(os.path.join(args.out, "include/iplan/msg/types.h"),
                         gen_header(p.order, p.consts))
        write_if_changed(os.path.join(args.out, "type_table.cc"), gen_type_table(p.order))
        write_if_changed(os.path.join(args.out, "fastdds_types.cc"), gen_fastdds(p.order, args.idl))
        write_if_changed(os.path.join(args.out, "fastdds_plain_types.cc"), gen_fastdds_plain(p.order))
        write_if_changed(os.path.join(args.out, "cyclone_types.cc"), gen_cyclone(p.order, args.idl))
    except IdlError as e:
        print(f"gen_msgs: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
