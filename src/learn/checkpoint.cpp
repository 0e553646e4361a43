#include "pinball/learn/checkpoint.h"

#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "pinball/core/json_text.h"
#include "pinball/learn/team.h"

namespace pinball::learn {
namespace {

// Format 2: a demonstration's shots field by field (format 1 wrote them with
// the struct's padding, whatever the memory held).
constexpr const char* kHeader = "pinball checkpoint 2";
constexpr const char* kOldHeader = "pinball checkpoint 1";
constexpr std::uint32_t kRecordMagic = 0x4B434250;  // "PBCK"

struct Tape {
  std::string path;
  std::vector<std::vector<Blob>> batches;  // read on resume (rank 0), replayed in order
  std::size_t next = 0;
  std::ofstream file;                      // rank 0: appends
  CheckpointStatus status;
};
std::unique_ptr<Tape> g_tape;

std::uint64_t fnv1a(const std::uint8_t* p, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

Blob encode_record(const std::vector<Blob>& batch) {
  BlobWriter w;
  w.put<std::uint32_t>(kRecordMagic).put<std::uint64_t>(batch.size());
  for (const Blob& b : batch) w.put_vector(b);
  Blob bytes = w.take();
  const std::uint64_t hash = fnv1a(bytes.data(), bytes.size());
  const auto* h = reinterpret_cast<const std::uint8_t*>(&hash);
  bytes.insert(bytes.end(), h, h + sizeof hash);
  return bytes;
}

// Reads whole records from `in` (after the header); returns the byte offset
// just past the last whole one.
std::streamoff read_records(std::ifstream& in, std::streamoff start, std::vector<std::vector<Blob>>& batches) {
  const Blob rest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  BlobReader r(rest);
  std::size_t good = 0;
  try {
    while (!r.at_end()) {
      if (r.get<std::uint32_t>() != kRecordMagic) break;
      const auto count = r.get<std::uint64_t>();
      std::vector<Blob> batch;
      for (std::uint64_t k = 0; k < count; ++k) batch.push_back(r.get_vector<std::uint8_t>());
      const std::size_t end = r.position();
      if (r.get<std::uint64_t>() != fnv1a(rest.data() + good, end - good)) break;
      good = r.position();
      batches.push_back(std::move(batch));
    }
  } catch (const std::runtime_error&) {
    // cut off mid-record: keep what came before
  }
  return start + static_cast<std::streamoff>(good);
}

// The keys of two fingerprints that are one label and a JSON object ("pinball learn {...}", as
// learn's are) whose values differ, "seed (1 recorded, 2 now), ...": two lines of thirty keys
// each had hidden the one that mattered. Empty when the labels differ or either is no object.
std::string differing_keys(const std::string& recorded, const std::string& now) {
  const std::size_t ra = recorded.find('{');
  const std::size_t nb = now.find('{');
  if (ra == std::string::npos || nb == std::string::npos || recorded.substr(0, ra) != now.substr(0, nb)) return "";
  const nlohmann::json a = nlohmann::json::parse(recorded.substr(ra), nullptr, false);
  const nlohmann::json b = nlohmann::json::parse(now.substr(nb), nullptr, false);
  if (!a.is_object() || !b.is_object()) return "";
  nlohmann::json keys = a;
  keys.update(b);
  std::string out;
  for (const auto& item : keys.items()) {
    const std::string& key = item.key();
    const std::string was = a.contains(key) ? json_text(a.at(key)) : "none";
    const std::string is = b.contains(key) ? json_text(b.at(key)) : "none";
    if (was == is) continue;
    out += (out.empty() ? "" : ", ") + key + " (" + was + " recorded, " + is + " now)";
  }
  return out;
}

// Rank 0: reads or creates the file; returns "" or what is wrong.
std::string open_on_root(const CheckpointOptions& o, Tape& tape) {
  namespace fs = std::filesystem;
  const std::string expected = std::string(kHeader) + "\n" + o.fingerprint + "\n";
  std::error_code ec;
  const bool exists = fs::exists(o.path, ec);
  if (!o.resume) {
    if (fs::is_directory(o.path, ec)) return "checkpoint " + o.path + " is a folder, not a file";
    if (exists && !fs::is_regular_file(o.path, ec)) {
      return "checkpoint " + o.path + " is not a regular file (a device, a pipe): it cannot hold a run";
    }
    if (exists) {
      return "checkpoint " + o.path + " already exists: pass --resume to continue that run, or remove the file to start again";
    }
    tape.file.open(o.path, std::ios::binary | std::ios::trunc);
    if (!tape.file) return "checkpoint " + o.path + ": cannot create it";
    tape.file << expected;
    tape.file.flush();
    if (!tape.file) return "checkpoint " + o.path + ": cannot write it";
    return "";
  }
  if (!exists) return "checkpoint " + o.path + ": no such file to resume (start the run with --checkpoint alone)";
  std::ifstream in(o.path, std::ios::binary);
  std::string header;
  std::string fingerprint;
  if (!std::getline(in, header)) header.clear();
  if (header == kOldHeader) {
    return "checkpoint " + o.path + " was written by an older build (format 1, this one writes 2): start the run "
           "again without --resume";
  }
  if (header != kHeader) {
    return "checkpoint " + o.path + ": not a pinball checkpoint (its first line is not '" + kHeader + "')";
  }
  if (!std::getline(in, fingerprint)) return "checkpoint " + o.path + ": cut off in its header";
  if (fingerprint != o.fingerprint) {
    const std::string keys = differing_keys(fingerprint, o.fingerprint);
    const std::string what =
        keys.empty() ? ": it recorded\n  " + fingerprint + "\nand this run is\n  " + o.fingerprint + "\n"
                     : " (they differ in " + keys + ") ";
    return "checkpoint " + o.path + " was written by another run" + what +
           "(the same command, seed and board files are needed; --threads may differ)";
  }
  const std::streamoff start = static_cast<std::streamoff>(expected.size());
  const std::streamoff good = read_records(in, start, tape.batches);
  in.close();
  const auto size = static_cast<std::streamoff>(fs::file_size(o.path, ec));
  if (good < size) {
    tape.status.dropped_bytes = static_cast<std::uint64_t>(size - good);
    fs::resize_file(o.path, static_cast<std::uintmax_t>(good), ec);
    if (ec) return "checkpoint " + o.path + ": cannot cut off its damaged last record: " + ec.message();
  }
  tape.status.batches_in_file = tape.batches.size();
  tape.file.open(o.path, std::ios::binary | std::ios::app);
  if (!tape.file) return "checkpoint " + o.path + ": cannot append to it";
  return "";
}

}  // namespace

void open_checkpoint(const CheckpointOptions& options) {
  g_tape.reset();
  if (options.path.empty()) return;
  auto tape = std::make_unique<Tape>();
  tape->path = options.path;
  std::string error;
  if (team_root()) error = open_on_root(options, *tape);
  // Every rank learns rank 0's verdict, so all stop or all go on.
  const std::vector<Blob> verdict = team_broadcast({Blob(error.begin(), error.end())});
  error.assign(verdict.front().begin(), verdict.front().end());
  if (!error.empty()) throw std::runtime_error(error);
  tape->status.open = true;
  g_tape = std::move(tape);
}

void close_checkpoint() { g_tape.reset(); }

CheckpointStatus checkpoint_status() { return g_tape ? g_tape->status : CheckpointStatus{}; }

bool checkpoint_replay(std::size_t count, std::vector<Blob>& out) {
  if (!g_tape) return false;
  Tape& t = *g_tape;
  // Rank 0 sends a flag blob ({1}: replayed, {0}: play it), then the batch.
  std::vector<Blob> message;
  if (team_root()) {
    if (t.next < t.batches.size()) {
      message.push_back(Blob{1});
      for (Blob& b : t.batches[t.next]) message.push_back(std::move(b));
      t.batches[t.next].clear();
    } else {
      message.push_back(Blob{0});
    }
  }
  message = team_broadcast(std::move(message));
  if (message.front() == Blob{0}) return false;
  if (message.size() - 1 != count) {
    throw std::runtime_error("checkpoint " + t.path + ": batch " + std::to_string(t.next + 1) + " has " +
                             std::to_string(message.size() - 1) + " results where this run plays " +
                             std::to_string(count) + ": it is not the run that wrote the file");
  }
  out.assign(std::make_move_iterator(message.begin() + 1), std::make_move_iterator(message.end()));
  ++t.next;
  ++t.status.replayed;
  t.status.replayed_items += count;
  return true;
}

void checkpoint_record(const std::vector<Blob>& batch) {
  if (!g_tape) return;
  Tape& t = *g_tape;
  ++t.next;  // this batch is past, in the file or not
  ++t.status.recorded;
  if (!team_root()) return;
  const Blob record = encode_record(batch);
  t.file.write(reinterpret_cast<const char*>(record.data()), static_cast<std::streamsize>(record.size()));
  t.file.flush();
  if (!t.file) throw std::runtime_error("checkpoint " + t.path + ": cannot write (disk full?)");
}

}  // namespace pinball::learn
