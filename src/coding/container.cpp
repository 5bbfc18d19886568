// Blocks of the .amc file: writing, and reading with every length and checksum verified.
#include "coding/container.h"

#include "common/check.h"
#include "common/little_endian.h"

#include <xxhash.h>

#include <cstring>

namespace amc {

const char* block_type_name(uint8_t type) {
    switch (BlockType(type)) {
        case BlockType::end: return "end";
        case BlockType::metadata: return "metadata";
        case BlockType::base_connectivity: return "base connectivity";
        case BlockType::base_geometry: return "base geometry";
        case BlockType::level: return "level";
        case BlockType::numbering: return "numbering";
        case BlockType::chunk_table: return "chunk table";
        case BlockType::seam: return "seam";
        case BlockType::chunk: return "chunk";
    }
    return "unknown";
}

namespace {
uint8_t amc_last_block_type(uint8_t version) {
    return version >= kChunkedVersion     ? uint8_t(BlockType::chunk)
           : version >= kNumberingVersion ? uint8_t(BlockType::numbering)
                                          : uint8_t(BlockType::level);
}
}  // namespace

const FileFraming kAmcFraming = {{kFileMagic[0], kFileMagic[1], kFileMagic[2], kFileMagic[3]}, ".amc", kOldestReadableVersion, kNewestVersion,
                                 kFlagSinglePrecision | kFlagQuantized, amc_last_block_type, block_type_name};

BlockWriter::BlockWriter(const FileFraming& framing, uint8_t version, uint8_t flags) : framing_(&framing) {
    out_.assign(framing.magic, framing.magic + 4);
    out_.push_back(version);
    out_.push_back(flags);
    out_.push_back(0);
    out_.push_back(0);
    append_le32(out_, XXH32(out_.data(), 8, 0));
}

void BlockWriter::add(uint8_t type, const std::vector<uint8_t>& payload) {
    AMC_REQUIRE(payload.size() <= UINT32_MAX, limit_exceeded,
                std::string(framing_->block_name(type)) + " block is larger than 4 GiB");
    const size_t start = out_.size();
    out_.push_back(uint8_t(type));
    append_le32(out_, uint32_t(payload.size()));
    out_.insert(out_.end(), payload.begin(), payload.end());
    // The checksum covers the type, the length and the payload.
    append_le32(out_, XXH32(out_.data() + start, out_.size() - start, 0));
}

std::vector<uint8_t> BlockWriter::finish() {
    add(uint8_t(BlockType::end), {});
    return std::move(out_);
}

BlockReader::BlockReader(const uint8_t* data, size_t size, const FileFraming& framing)
    : framing_(&framing), data_(data), size_(size) {
    const std::string ext = framing.extension;
    AMC_REQUIRE(size >= 4 && std::memcmp(data, framing.magic, 4) == 0, bad_magic, "not an " + ext + " file (bad magic)");
    AMC_REQUIRE(size >= 5, truncated, "file is truncated (header)");
    version_ = data[4];
    // The version comes first: a newer file may have a header this build does not know.
    AMC_REQUIRE(version_ <= framing.newest_version, unsupported_version,
                "unsupported " + ext + " version " + std::to_string(version_) + " (newer than this build, which reads versions " +
                    std::to_string(framing.oldest_version) + " to " + std::to_string(framing.newest_version) + ")");
    AMC_REQUIRE(version_ >= framing.oldest_version, corrupt, "unknown " + ext + " version " + std::to_string(version_));
    AMC_REQUIRE(size >= kFileHeaderSize, truncated, "file is truncated (header)");
    AMC_REQUIRE(XXH32(data, 8, 0) == load_le32(data + 8), checksum, "checksum mismatch in the file header");
    flags_ = data[5];
    AMC_REQUIRE(!(flags_ & ~framing.known_flags), corrupt, "unknown flags in the file header");
    AMC_REQUIRE(data[6] == 0 && data[7] == 0, corrupt, "reserved header bytes are not zero");
}

bool BlockReader::next_block_arrived() const {
    return size_ - pos_ >= kBlockOverhead && load_le32(data_ + pos_ + 1) <= size_ - pos_ - kBlockOverhead;
}

bool BlockReader::next(Block& block) { return read(block, true); }

bool BlockReader::next_unchecked(Block& block) { return read(block, false); }

void BlockReader::check_checksum(const Block& block) const {
    const uint8_t* header = data_ + block.offset;
    AMC_REQUIRE(XXH32(header, 5 + block.size, 0) == load_le32(header + 5 + block.size), checksum,
                "checksum mismatch in the " + std::string(framing_->block_name(uint8_t(block.type))) + " block at byte " +
                    std::to_string(block.offset));
}

bool BlockReader::read(Block& block, bool checked) {
    if (ended_) return false;
    AMC_REQUIRE(size_ - pos_ >= kBlockOverhead, truncated,
                "file is truncated (block header at byte " + std::to_string(pos_) + ")");
    const uint8_t type = data_[pos_];
    const uint32_t length = load_le32(data_ + pos_ + 1);
    AMC_REQUIRE(length <= size_ - pos_ - kBlockOverhead, truncated,
                "file is truncated (" + std::string(framing_->block_name(type)) + " block at byte " +
                    std::to_string(pos_) + " announces " + std::to_string(length) + " bytes)");
    block = {BlockType(type), data_ + pos_ + 5, length, pos_};
    // A bad checksum is the problem to name, before what the bad bytes seem to say.
    const bool malformed = type > framing_->last_block_type(version_) ||
                           (type == uint8_t(BlockType::end) && (length != 0 || pos_ + kBlockOverhead != size_));
    if (checked || malformed) check_checksum(block);
    AMC_REQUIRE(type <= framing_->last_block_type(version_), corrupt, "unknown block type " + std::to_string(type));
    pos_ += kBlockOverhead + length;
    if (block.type == BlockType::end) {
        ended_ = true;
        AMC_REQUIRE(length == 0, corrupt, "end block is not empty");
        AMC_REQUIRE(pos_ == size_, corrupt, std::to_string(size_ - pos_) + " bytes after the end block");
    }
    return true;
}

void BlockReader::seek(size_t offset) {
    AMC_REQUIRE(offset >= kFileHeaderSize && offset <= size_, corrupt,
                "block offset " + std::to_string(offset) + " lies outside the file");
    pos_ = offset;
    ended_ = false;
}

void put_varint(std::vector<uint8_t>& out, uint64_t value) {
    do {
        out.push_back(uint8_t((value & 0x7f) | (value > 0x7f ? 0x80 : 0)));
        value >>= 7;
    } while (value != 0);
}

void put_f64(std::vector<uint8_t>& out, double value) { append_le64(out, bit_cast<uint64_t>(value)); }

void PayloadReader::fail(ErrorCode code, const std::string& problem) const {
    throw_error(code, std::string(what_) + ": " + problem);
}

VarintRead read_varint(const uint8_t* data, size_t size, size_t& pos, uint64_t& value, int max_bits) {
    value = 0;
    for (int shift = 0;; shift += 7) {
        if (pos >= size) return VarintRead::truncated;
        if (shift >= max_bits) return VarintRead::too_long;
        const uint8_t byte = data[pos++];
        if (shift + 7 > max_bits && (byte >> (max_bits - shift)) != 0) return VarintRead::too_long;
        value |= uint64_t(byte & 0x7f) << shift;
        if (!(byte & 0x80)) return VarintRead::ok;
    }
}

uint64_t PayloadReader::varint() {
    uint64_t value = 0;
    switch (read_varint(data_, size_, pos_, value)) {
        case VarintRead::ok: break;
        case VarintRead::truncated: fail(ErrorCode::truncated, "truncated number");
        case VarintRead::too_long: fail(ErrorCode::corrupt, "number too long");
    }
    return value;
}

uint8_t PayloadReader::u8() {
    if (pos_ >= size_) fail(ErrorCode::truncated, "truncated");
    return data_[pos_++];
}

const uint8_t* PayloadReader::bytes(uint64_t count) {
    if (count > size_ - pos_) fail(ErrorCode::truncated, "truncated");
    const uint8_t* start = data_ + pos_;
    pos_ += size_t(count);
    return start;
}

double PayloadReader::f64() {
    if (size_ - pos_ < 8) fail(ErrorCode::truncated, "truncated");
    const double value = bit_cast<double>(load_le64(data_ + pos_));
    pos_ += 8;
    return value;
}

}  // namespace amc
