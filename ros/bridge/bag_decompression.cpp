#include "ros/bridge/bag_decompression.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <memory>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// Output buffers start at 64 KiB and double up to `limit` bytes.
void Grow(std::string& out, std::size_t limit) {
  out.resize(std::min(limit, std::max<std::size_t>(2 * out.size(), std::size_t{1} << 16)));
}

// Makes room after `used` bytes of `out`; `size` + 1 bytes at most, so that a stream giving
// more than its chunk says is caught on its first extra byte.
void MakeRoom(std::string& out, std::size_t used, std::size_t size) {
  if (used < out.size()) return;
  if (out.size() > size) {
    throw Error("the data decompresses to more than the chunk's " + std::to_string(size) +
                " bytes");
  }
  Grow(out, size + 1);
}

void CheckSize(std::size_t produced, std::size_t size) {
  if (produced != size) {
    throw Error("the data decompresses to " + std::to_string(produced) + " bytes, the chunk says " +
                std::to_string(size));
  }
}

std::string DecompressLz4(std::string_view data, std::size_t size) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
    throw Error("lz4: no decompression context");
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(
      raw, LZ4F_freeDecompressionContext);
  std::string out;
  std::size_t in_at = 0, out_at = 0;
  for (;;) {
    MakeRoom(out, out_at, size);
    std::size_t produced = out.size() - out_at, consumed = data.size() - in_at;
    const std::size_t hint = LZ4F_decompress(context.get(), out.data() + out_at, &produced,
                                             data.data() + in_at, &consumed, nullptr);
    if (LZ4F_isError(hint))
      throw Error(std::string("damaged lz4 data (") + LZ4F_getErrorName(hint) + ")");
    in_at += consumed;
    out_at += produced;
    if (hint == 0) break;  // the frame is complete (its checksum, when it has one, verified)
    if (consumed == 0 && produced == 0) throw Error("the lz4 data ends inside its frame");
  }
  if (in_at != data.size())
    throw Error(std::to_string(data.size() - in_at) + " bytes after the lz4 frame");
  CheckSize(out_at, size);
  out.resize(out_at);
  return out;
}

std::string DecompressBz2(std::string_view data, std::size_t size) {
  bz_stream stream{};
  if (BZ2_bzDecompressInit(&stream, 0, 0) != BZ_OK) throw Error("bz2: no decompression stream");
  const std::unique_ptr<bz_stream, int (*)(bz_stream*)> end(&stream, BZ2_bzDecompressEnd);
  stream.next_in =
      const_cast<char*>(data.data());  // bzlib's API is not const-correct; it only reads
  stream.avail_in =
      static_cast<unsigned int>(data.size());  // a chunk's data is at most 4 GB (uint32)
  std::string out;
  std::size_t out_at = 0;
  for (;;) {
    MakeRoom(out, out_at, size);
    stream.next_out = out.data() + out_at;
    stream.avail_out = static_cast<unsigned int>(out.size() - out_at);
    const int rc = BZ2_bzDecompress(&stream);
    out_at = out.size() - stream.avail_out;
    if (rc == BZ_STREAM_END) break;  // every block's CRC and the stream's verified
    if (rc != BZ_OK) throw Error("damaged bz2 data (bzip2 error " + std::to_string(rc) + ")");
    if (stream.avail_in == 0 && stream.avail_out > 0)
      throw Error("the bz2 data ends inside its stream");
  }
  if (stream.avail_in != 0)
    throw Error(std::to_string(stream.avail_in) + " bytes after the bz2 stream");
  CheckSize(out_at, size);
  out.resize(out_at);
  return out;
}

}  // namespace

std::string DecompressBagChunk(std::string_view compression, std::string_view data,
                               std::size_t size) {
  if (size > kMaxBagChunkBytes) {
    throw Error("a chunk of " + std::to_string(size) + " bytes, more than uwscan reads (" +
                std::to_string(kMaxBagChunkBytes) + ")");
  }
  if (compression == "none") {
    if (data.size() != size) {
      throw Error("an uncompressed chunk of " + std::to_string(data.size()) +
                  " bytes, its header says " + std::to_string(size));
    }
    return std::string(data);
  }
  if (compression == "lz4") return DecompressLz4(data, size);
  if (compression == "bz2") return DecompressBz2(data, size);
  throw Error("chunk compression '" + std::string(compression) +
              "' (uwscan reads none, bz2 and lz4)");
}

}  // namespace uwscan::ros
