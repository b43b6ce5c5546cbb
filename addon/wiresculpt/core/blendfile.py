"""Reads a .blend file's blocks and its SDNA (the struct layouts the file describes itself with),
and sets which tab a 3D view's sidebar opens on, for Blenders whose Python cannot (3.4 has no
`Region.active_panel_category`; 4.2 has it).

The .blend format (doc: developer.blender.org, "The Blender file format"): a 12-byte header
"BLENDER" + pointer size ('-' 8, '_' 4) + endianness ('v' little, 'V' big) + version; then blocks,
each a head (code[4], length int32, old address, SDNA index int32, count int32) and `length`
bytes; the "DNA1" block lists every struct's fields with their types, so field offsets are
computed from the file itself, never assumed. Blocks coded "DATA" that follow an ID's block
belong to that ID; a pointer in a block holds the old address of the block it points to.

A region remembers its sidebar tab in `ARegion.panels_category_active`, a list of
`PanelCategoryStack {next, prev, idname[64]}` that Blender saves and reads back. set_sidebar_tab
appends one such block after each 3D view's sidebar region and points the list at it.

bpy-free: the batch run calls it after saving; the tests read files with it.
"""
import gzip
import os
import struct

SPACE_VIEW3D = 1  # eSpace_Type
RGN_TYPE_UI = 4  # eRegion_Type: the sidebar


class BlendFile:
    def __init__(self, data):
        if data[:2] == b"\x1f\x8b":
            data = gzip.decompress(data)
        if data[:7] != b"BLENDER":
            if data[:4] == b"\x28\xb5\x2f\xfd":
                raise ValueError("this .blend file is zstd-compressed: save it without compression to read it")
            raise ValueError("not a .blend file (no BLENDER header)")
        if data[7:8] not in (b"-", b"_") or data[8:9] not in (b"v", b"V"):
            raise ValueError(f"a .blend header this reader does not know: {bytes(data[:17])!r}")
        self.pointer_size = 8 if data[7:8] == b"-" else 4
        self.endian = "<" if data[8:9] == b"v" else ">"
        self.version = data[9:12].decode()
        self.data = bytearray(data)
        self.head_size = 16 + self.pointer_size
        self.blocks = []  # (code, head offset, data offset, length, old address, sdna index, count)
        offset = 12
        while offset + self.head_size <= len(data):
            code = bytes(data[offset:offset + 4])
            length, = struct.unpack_from(self.endian + "i", data, offset + 4)
            old = self.pointer(offset + 8)
            sdna, count = struct.unpack_from(self.endian + "ii", data, offset + 8 + self.pointer_size)
            self.blocks.append((code, offset, offset + self.head_size, length, old, sdna, count))
            if code == b"ENDB":
                break
            offset += self.head_size + length
        self.by_address = {b[4]: b for b in self.blocks if b[0] != b"ENDB"}
        self._read_sdna()

    def pointer(self, offset):
        return struct.unpack_from(self.endian + ("Q" if self.pointer_size == 8 else "I"), self.data, offset)[0]

    def _read_sdna(self):
        [dna] = [b for b in self.blocks if b[0] == b"DNA1"]
        d, at = self.data, dna[2]
        e = self.endian

        def expect(tag):
            nonlocal at
            at = (at + 3) & ~3
            if bytes(d[at:at + 4]) != tag:
                raise ValueError(f"SDNA: expected {tag!r} at {at}")
            at += 4

        def strings():
            nonlocal at
            count, = struct.unpack_from(e + "i", d, at)
            at += 4
            out = []
            for _ in range(count):
                end = d.index(0, at)
                out.append(d[at:end].decode("latin-1"))
                at = end + 1
            return out

        expect(b"SDNA")
        expect(b"NAME")
        names = strings()
        expect(b"TYPE")
        types = strings()
        expect(b"TLEN")
        lengths = struct.unpack_from(e + f"{len(types)}h", d, at)
        at += 2 * len(types)
        expect(b"STRC")
        count, = struct.unpack_from(e + "i", d, at)
        at += 4
        self.struct_names = []
        self.structs = {}  # name -> (sdna index, size, {field: (offset, size, type)})
        for index in range(count):
            type_index, nfields = struct.unpack_from(e + "hh", d, at)
            at += 4
            fields, offset = {}, 0
            for _ in range(nfields):
                field_type, field_name = struct.unpack_from(e + "hh", d, at)
                at += 4
                name = names[field_name]
                if name.startswith("*") or name.startswith("(*"):
                    size = self.pointer_size
                else:
                    size = lengths[field_type]
                dims = 1
                for part in name.split("[")[1:]:
                    dims *= int(part.rstrip("]"))
                key = name.split("[")[0].lstrip("*(").rstrip(")")
                if key.endswith(")()"):
                    key = key[:-3]
                fields[key] = (offset, size * dims, types[field_type])
                offset += size * dims
            self.struct_names.append(types[type_index])
            self.structs[types[type_index]] = (index, lengths[type_index], fields)

    def field(self, struct_name, field):
        """(offset, size) of a field of a struct, from this file's SDNA."""
        offset, size, _type = self.structs[struct_name][2][field]
        return offset, size

    def read_int(self, block, struct_name, field, index=0):
        offset, size = self.field(struct_name, field)
        fmt = {1: "b", 2: "h", 4: "i", 8: "q"}[size]
        size_one = struct.calcsize(fmt)
        base = block[2] + index * self.structs[struct_name][1]
        return struct.unpack_from(self.endian + fmt, self.data, base + offset)[0] if size_one == size else None

    def read_pointer(self, block, struct_name, field):
        offset, _size = self.field(struct_name, field)
        return self.pointer(block[2] + offset)

    def read_string(self, block, struct_name, field):
        offset, size = self.field(struct_name, field)
        raw = bytes(self.data[block[2] + offset:block[2] + offset + size])
        return raw.split(b"\0")[0].decode("utf-8", "replace")

    def walk(self, first):
        """The blocks of a linked list (ListBase.first, each element's first field `next`)."""
        seen = set()
        while first and first in self.by_address and first not in seen:
            seen.add(first)
            block = self.by_address[first]
            yield block
            first = self.pointer(block[2])  # `next` is the first field of every list element

    def screens(self):
        """[(screen name, screen block)] of every bScreen."""
        out = []
        for b in self.blocks:
            if b[0].rstrip(b"\0") == b"SN" and self.struct_names[b[5]] == "bScreen":
                out.append((self._id_name(b), b))
        return out

    def _id_name(self, block):
        # bScreen starts with an ID whose `name[66]` holds the type code and the name ("SRLayout")
        id_offset, _ = self.field("bScreen", "id")
        name_offset, name_size = self.field("ID", "name")
        start = block[2] + id_offset + name_offset
        return bytes(self.data[start:start + name_size]).split(b"\0")[0].decode("utf-8", "replace")[2:]

    def view3d_sidebars(self):
        """[(screen name, region block)] of the sidebar region of every 3D view area."""
        out = []
        areabase, _ = self.field("bScreen", "areabase")
        for name, screen in self.screens():
            for area in self.walk(self.pointer(screen[2] + areabase)):
                if self.read_int(area, "ScrArea", "spacetype") != SPACE_VIEW3D:
                    continue
                regionbase, _ = self.field("ScrArea", "regionbase")
                for region in self.walk(self.pointer(area[2] + regionbase)):
                    if self.read_int(region, "ARegion", "regiontype") == RGN_TYPE_UI:
                        out.append((name, region))
        return out

    def sidebar_tabs(self, region):
        """The tab stack a sidebar region remembers (most recent first)."""
        offset, _ = self.field("ARegion", "panels_category_active")
        return [self.read_string(b, "PanelCategoryStack", "idname")
                for b in self.walk(self.pointer(region[2] + offset))]


def read(path):
    with open(path, "rb") as f:
        return BlendFile(f.read())


def set_sidebar_tab(path, tab):
    """Makes every 3D view's sidebar in the .blend at `path` (uncompressed or gzip; rewritten
    uncompressed, atomically) open on `tab` (a panel's bl_category, e.g. "Wire"). Returns the
    number of sidebars set."""
    blend = read(path)
    if len(tab.encode()) >= 64:
        raise ValueError(f"a sidebar tab name has at most 63 bytes: {tab!r}")
    index, size, _fields = blend.structs["PanelCategoryStack"]
    name_offset, name_size = blend.field("PanelCategoryStack", "idname")
    first_offset, _ = blend.field("ARegion", "panels_category_active")
    e, ptr = blend.endian, ("Q" if blend.pointer_size == 8 else "I")
    regions = blend.view3d_sidebars()
    # a fresh old address for each new block: above every address in the file, 8-aligned
    address = (max(blend.by_address) + 0x10000) & ~7
    inserts = {}  # head offset of the block after which a new block goes -> bytes
    data = blend.data
    for _name, region in regions:
        address += 0x100
        body = bytearray(size)  # next = prev = NULL: the region's only remembered tab
        body[name_offset:name_offset + len(tab.encode())] = tab.encode()
        head = b"DATA" + struct.pack(e + "i", size) + struct.pack(e + ptr, address) + struct.pack(e + "ii", index, 1)
        inserts[region[1]] = head + bytes(body)
        # ListBase {first, last} of the region points at the new block
        struct.pack_into(e + ptr + ptr, data, region[2] + first_offset, address, address)
    out = bytearray(data[:12])
    for b in blend.blocks:
        end = b[2] + b[3] if b[0] != b"ENDB" else len(data)
        out += data[b[1]:end]
        out += inserts.get(b[1], b"")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(out)
    os.replace(tmp, path)
    return len(regions)
