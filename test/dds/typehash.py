#!/usr/bin/env python3
"""ROS 2's type hash (REP-2011, "RIHS01") of every message type of tools/j288-dds/idl, computed
here from the IDL itself (preprocessed by `idlc -E -DJ288_DDS_AS_ROS2`: the types as ROS 2
declares them, unbounded) and the REP's rules, apart from the bridge's own tables
(tools/j288-dds/typehash.c), which test/dds/golden.sh compares with this:

- a type's description: its name ("pkg/msg/Name": the IDL's module path without "dds_", the
  struct's name without its trailing "_") and its fields, each with its name and type: the
  type id (type_description_interfaces/msg/FieldType: int8 2, uint8 3, int16 4, uint16 5,
  int32 6, uint32 7, float 10, double 11, octet (ROS 2's byte) 16, string 17, a nested type 1;
  plus 48 for a fixed array, 144 for an unbounded sequence), the capacity (an array's size),
  the string capacity (0: unbounded) and the nested type's name ("" if none);
- the hashed text: JSON {"type_description": ..., "referenced_type_descriptions": [...]}
  with every type the described one refers to, directly or not, sorted by name; no default
  values; separators ", " and ": ";
- the hash: "RIHS01_" and the SHA-256 of that text in lowercase hex.

Prints 'NAME RIHS01_...' for every top-level type the bridge puts on DDS.
usage: typehash.py IDL_DIR"""
import hashlib
import json
import os
import re
import subprocess
import sys

BASE_IDS = {'int8': 2, 'uint8': 3, 'int16': 4, 'uint16': 5, 'int32': 6, 'uint32': 7,
            'float': 10, 'double': 11, 'octet': 16, 'string': 17}
TOP = ['sensor_msgs/msg/JointState', 'diagnostic_msgs/msg/DiagnosticArray',
       'unitree_go/msg/LowCmd', 'unitree_go/msg/LowState',
       'unitree_hg/msg/LowCmd', 'unitree_hg/msg/LowState']
FILES = ['builtin_interfaces', 'std_msgs', 'sensor_msgs', 'diagnostic_msgs', 'unitree_go',
         'unitree_hg']


def ros_name(scoped):
    """unitree_go::msg::dds_::MotorCmd_ -> unitree_go/msg/MotorCmd"""
    parts = [p for p in scoped.split('::') if p and p != 'dds_']
    parts[-1] = parts[-1].rstrip('_')
    return '/'.join(parts)


def parse(text):
    """{type name: [(field, type_id, capacity, nested)]} from preprocessed IDL."""
    text = re.sub(r'//[^\n]*|^#[^\n]*', '', text, flags=re.M)
    types = {}
    module = []
    tokens = re.findall(r'module\s+\w+\s*\{|@\w+|struct\s+\w+\s*\{|\}\s*;|[^;{}]+;', text)
    current = None
    for tok in tokens:
        tok = tok.strip()
        if tok.startswith('module'):
            module.append(tok.split()[1].rstrip('{'))
        elif tok.startswith('@'):
            continue
        elif tok.startswith('struct'):
            current = ros_name('::'.join(module + [tok.split()[1].rstrip('{')]))
            types[current] = []
        elif re.match(r'\}\s*;', tok):
            if current is not None:
                current = None
            else:
                module.pop()
        else:
            m = re.match(r'(sequence\s*<\s*([\w:]+)\s*>|[\w:]+)\s+(\w+)\s*(\[(\d+)\])?\s*;$', tok)
            if not m:
                sys.exit('typehash.py: cannot read %r' % tok)
            element = m.group(2) or m.group(1)
            nested = '' if element in BASE_IDS else ros_name(element)
            tid = 1 if nested else BASE_IDS[element]
            cap = 0
            if m.group(2):
                tid += 144
            elif m.group(5):
                tid += 48
                cap = int(m.group(5))
            types[current].append((m.group(3), tid, cap, nested))
    return types


def description(name, types):
    return {'type_name': name,
            'fields': [{'name': f, 'type': {'type_id': t, 'capacity': c, 'string_capacity': 0,
                                            'nested_type_name': n}} for f, t, c, n in types[name]]}


def rihs01(name, types):
    refs, queue = set(), [n for _, _, _, n in types[name] if n]
    while queue:
        t = queue.pop()
        if t not in refs:
            refs.add(t)
            queue += [n for _, _, _, n in types[t] if n]
    text = json.dumps({'type_description': description(name, types),
                       'referenced_type_descriptions': [description(t, types) for t in sorted(refs)]},
                      separators=(', ', ': '))
    return 'RIHS01_' + hashlib.sha256(text.encode()).hexdigest()


if __name__ == '__main__':
    idl_dir = sys.argv[1]
    types = {}
    for f in FILES:
        if not os.path.exists('%s/%s.idl' % (idl_dir, f)):
            continue  # a type whose IDL is not there gets no line (golden.sh then fails on it)
        out = subprocess.run(['idlc', '-E', '-DJ288_DDS_AS_ROS2', '-I', idl_dir,
                              '%s/%s.idl' % (idl_dir, f)], check=True, capture_output=True, text=True)
        types.update(parse(out.stdout))
    for name in TOP:
        if name in types:
            print(name, rihs01(name, types))
