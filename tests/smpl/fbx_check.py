"""Checks the node structure of a binary FBX file the way Blender's FBX importer reads it
(io_scene_fbx/parse_fbx.py): every node record's end offset lies inside the file, a node with
children closes its list with a null record (13 bytes, or 25 from version 7500), the top-level
list ends with a null record. Prints one line per problem and exits 1 if there is any, else
prints a summary and exits 0. Usage: python3 fbx_check.py FILE.fbx"""
import struct
import sys


def main(path):
    data = open(path, 'rb').read()
    if not data.startswith(b'Kaydara FBX Binary  \x00'):
        print(f'{path}: not a binary FBX file')
        return 1
    version = struct.unpack_from('<I', data, 23)[0]
    wide = version >= 7500
    head = '<QQQB' if wide else '<IIIB'
    head_size = struct.calcsize(head)
    null = b'\x00' * (head_size - 1)
    problems = []
    count = 0

    def read(offset, path_so_far):
        nonlocal count
        end, _, prop_len, name_len = struct.unpack_from(head, data, offset)
        if end == 0:
            return None
        if end > len(data) or end <= offset:
            problems.append(f'{path_so_far}: record at {offset} ends at {end}, outside the file')
            return None
        name = data[offset + head_size:offset + head_size + name_len].decode('ascii', 'replace')
        count += 1
        pos = offset + head_size + name_len + prop_len
        if pos < end:
            while pos < end - len(null):
                nxt = read(pos, path_so_far + '/' + name)
                if nxt is None:
                    break
                pos = nxt
            if data[end - len(null):end] != null:
                problems.append(f'{path_so_far}/{name}: the nested list does not end with a '
                                'null record (Blender: "failed to read nested block sentinel")')
        return end

    pos = 27
    while True:
        if data[pos:pos + len(null)] == null:
            break
        nxt = read(pos, '')
        if nxt is None:
            problems.append(f'top level: no null record closes the node list (at {pos})')
            break
        pos = nxt
    for p in problems:
        print(f'{path}: {p}')
    if not problems:
        print(f'{path}: FBX {version}, {count} nodes, every nested list closed by a null record')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1]))
