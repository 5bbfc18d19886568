// The block structure of the .amc file (docs/FORMAT.md, section 3): a fixed, checksummed header, then typed
// blocks, each with its length and an XXH32 checksum, ending with an END block.
#pragma once

#include "coding/format_version.h"

#include <amc/mesh.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

constexpr char kFileMagic[4] = {'A', 'M', 'C', 'F'};
constexpr size_t kFileHeaderSize = 12;  // magic, version, flags, 2 reserved, XXH32 of those 8
constexpr size_t kBlockOverhead = 1 + 4 + 4;  // type, payload length, checksum

// Block types: frozen values (they are written to files).
enum class BlockType : uint8_t {
    end = 0,
    metadata = 1,
    base_connectivity = 2,
    base_geometry = 3,
    level = 4,
    numbering = 5,
    chunk_table = 6,  // version 7 on: the chunks of roots and where their blocks are (FORMAT.md 3.11)
    seam = 7,         // version 7 on: the vertices on edges between chunks
    chunk = 8,        // version 7 on: one chunk's levels
};
const char* block_type_name(uint8_t type);

// The framing of one kind of file: the .amc file (kAmcFraming) and the octree forest file (.amq,
// src/octree/octree_file.h) share the header and block layout and differ in these.
struct FileFraming {
    char magic[4];
    const char* extension;  // ".amc": messages say "not an .amc file"
    uint8_t oldest_version, newest_version;
    uint8_t known_flags;
    uint8_t (*last_block_type)(uint8_t version);  // the highest block type a version may hold
    const char* (*block_name)(uint8_t type);
};
extern const FileFraming kAmcFraming;

// File header flags.
constexpr uint8_t kFlagSinglePrecision = 1;
constexpr uint8_t kFlagQuantized = 2;

class BlockWriter {
public:
    BlockWriter(uint8_t version, uint8_t flags) : BlockWriter(kAmcFraming, version, flags) {}
    BlockWriter(const FileFraming& framing, uint8_t version, uint8_t flags);
    void add(BlockType type, const std::vector<uint8_t>& payload) { add(uint8_t(type), payload); }
    void add(uint8_t type, const std::vector<uint8_t>& payload);
    std::vector<uint8_t> finish();  // appends the END block
    size_t size() const { return out_.size(); }

private:
    const FileFraming* framing_;
    std::vector<uint8_t> out_;
};

struct Block {
    BlockType type;
    const uint8_t* payload;
    size_t size;
    size_t offset;  // of the block header in the file
};

// Validates the header and walks the blocks; every length and checksum is checked before use.
class BlockReader {
public:
    // Throws Error on a bad header, and on a version outside kOldestReadableVersion .. kNewestVersion.
    BlockReader(const uint8_t* data, size_t size) : BlockReader(data, size, kAmcFraming) {}
    // The same for another kind of file.
    BlockReader(const uint8_t* data, size_t size, const FileFraming& framing);
    uint8_t flags() const { return flags_; }
    uint8_t version() const { return version_; }
    // The next block; throws Error on truncation, a bad checksum, an unknown type, or bytes after
    // END. Returns false after END.
    bool next(Block& block);
    // The same without the checksum, which the caller checks with check_checksum before it reads
    // the payload: chunk blocks are checked by the thread that decodes them.
    bool next_unchecked(Block& block);
    // Throws Error when `block` (of this file) does not match its checksum.
    void check_checksum(const Block& block) const;
    // Bytes after the blocks read so far.
    size_t remaining() const { return size_ - pos_; }
    // Whether the bytes left hold the next block whole (header, payload and checksum): false in
    // a file cut while that block was being written or received.
    bool next_block_arrived() const;
    // Continues at `offset` (a block header) instead: a reader that seeks straight to a block it
    // knows from a table. Throws Error if the offset lies outside the blocks.
    void seek(size_t offset);

private:
    bool read(Block& block, bool checked);

    const FileFraming* framing_;
    const uint8_t* data_;
    size_t size_;
    size_t pos_ = kFileHeaderSize;
    uint8_t flags_ = 0, version_ = 0;
    bool ended_ = false;
};

// Little helpers for payloads: LEB128 varints and fixed-size values.
void put_varint(std::vector<uint8_t>& out, uint64_t value);
void put_f64(std::vector<uint8_t>& out, double value);

// The one LEB128 reader: the number at data[pos] (pos moves past what was read), of at most
// `max_bits` bits (1..64). Longer numbers are too_long, numbers cut by the data's end truncated.
enum class VarintRead : uint8_t { ok, truncated, too_long };
VarintRead read_varint(const uint8_t* data, size_t size, size_t& pos, uint64_t& value, int max_bits = 64);

class PayloadReader {
public:
    PayloadReader(const uint8_t* data, size_t size, const char* what) : data_(data), size_(size), what_(what) {}
    uint64_t varint();
    uint8_t u8();
    double f64();
    // The next `count` bytes, which the caller then reads in place.
    const uint8_t* bytes(uint64_t count);
    size_t position() const { return pos_; }
    const uint8_t* rest() const { return data_ + pos_; }
    size_t remaining() const { return size_ - pos_; }

private:
    [[noreturn]] void fail(ErrorCode code, const std::string& problem) const;
    const uint8_t* data_;
    size_t size_;
    const char* what_;
    size_t pos_ = 0;
};

}  // namespace amc
