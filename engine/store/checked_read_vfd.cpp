// The readers' HDF5 virtual file driver ("kscheckedread", read-only): plain pread()s, like HDF5's
// sec2 driver, except that every global heap collection is checked before HDF5 parses it (see
// store/journal/heap_check.hpp). HDF5 1.10 trusts a collection's object sizes: an object whose size runs past
// its collection makes H5HG_read copy from beyond the collection or dereference a null object (a crash
// on a damaged file). Without metadata accumulation, HDF5 asks for each collection in one read at its
// address (a first read of its minimum size, then the whole collection; typed H5FD_MEM_DRAW, as HDF5
// reads global heaps like raw data), so the check sees collections whole.
#include "store/checked_read_vfd.hpp"
#include "store/h5util.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <map>
#include <mutex>
#include <vector>

namespace ks::store::detail {

namespace {

struct CFile {
  H5FD_t pub;  // first: HDF5 casts between H5FD_t* and CFile*
  int fd = -1;
  haddr_t eoa = 0, eof = 0;
  dev_t dev = 0;
  ino_t ino = 0;
};

bool pread_all(int fd, unsigned char* out, std::size_t size, std::uint64_t at) {
  while (size > 0) {
    const ssize_t n = ::pread(fd, out, size, static_cast<off_t>(at));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    if (n == 0) {  // past the end of the file: zeros, as sec2 reads
      std::memset(out, 0, size);
      return true;
    }
    out += n, at += static_cast<std::uint64_t>(n), size -= static_cast<std::size_t>(n);
  }
  return true;
}

std::map<std::uint64_t, std::uint64_t> collection_objects(int fd, std::uint64_t addr, std::uint64_t eof) {
  std::map<std::uint64_t, std::uint64_t> objects;
  unsigned char head[16];
  if (addr > eof || eof - addr < sizeof head || !pread_all(fd, head, sizeof head, addr)) return objects;
  const auto read = [fd](unsigned char* to, std::size_t n, std::uint64_t at) { return pread_all(fd, to, n, at); };
  if (std::memcmp(head, "GCOL\1\0\0\0", 8) != 0 || !global_heap_collection_is_sound(head, sizeof head, addr, eof, read))
    return objects;
  std::vector<unsigned char> whole(static_cast<std::size_t>(le(head + 8, 8)));
  if (!pread_all(fd, whole.data(), whole.size(), addr)) return objects;
  for (std::uint64_t p = 16; p + 16 <= whole.size();) {  // sound: every step advances and stays inside
    const std::uint64_t index = le(whole.data() + p, 2), size = le(whole.data() + p + 8, 8);
    if (index != 0) objects[index] = size;
    p += index == 0 ? size : 16 + (size + 7) / 8 * 8;
  }
  return objects;
}

H5FD_t* c_open(const char* name, unsigned flags, hid_t, haddr_t maxaddr) {
  if ((flags & H5F_ACC_RDWR) || (flags & H5F_ACC_CREAT) || (flags & H5F_ACC_TRUNC)) return nullptr;
  if (maxaddr == 0 || maxaddr == HADDR_UNDEF) return nullptr;
  const int fd = ::open(name, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return nullptr;
  struct stat st{};
  if (::fstat(fd, &st) != 0) {
    ::close(fd);
    return nullptr;
  }
  auto* f = new CFile{};
  f->fd = fd;
  f->eof = static_cast<haddr_t>(st.st_size);
  f->dev = st.st_dev;
  f->ino = st.st_ino;
  return &f->pub;
}

herr_t c_close(H5FD_t* file) {
  auto* f = reinterpret_cast<CFile*>(file);
  const int rc = ::close(f->fd);
  delete f;
  return rc == 0 ? 0 : -1;
}

int c_cmp(const H5FD_t* a, const H5FD_t* b) {
  auto* f1 = reinterpret_cast<const CFile*>(a);
  auto* f2 = reinterpret_cast<const CFile*>(b);
  if (f1->dev != f2->dev) return f1->dev < f2->dev ? -1 : 1;
  if (f1->ino != f2->ino) return f1->ino < f2->ino ? -1 : 1;
  return 0;
}

herr_t c_query(const H5FD_t*, unsigned long* flags) {
  *flags = H5FD_FEAT_DATA_SIEVE;  // no metadata accumulation: each collection arrives in a read of its own
  return 0;
}

haddr_t c_get_eoa(const H5FD_t* file, H5FD_mem_t) { return reinterpret_cast<const CFile*>(file)->eoa; }
herr_t c_set_eoa(H5FD_t* file, H5FD_mem_t, haddr_t addr) {
  reinterpret_cast<CFile*>(file)->eoa = addr;
  return 0;
}
haddr_t c_get_eof(const H5FD_t* file, H5FD_mem_t) { return reinterpret_cast<const CFile*>(file)->eof; }
herr_t c_get_handle(H5FD_t* file, hid_t, void** handle) {
  *handle = &reinterpret_cast<CFile*>(file)->fd;
  return 0;
}

herr_t c_read(H5FD_t* file, H5FD_mem_t type, hid_t, haddr_t addr, size_t size, void* buffer) {
  auto* f = reinterpret_cast<CFile*>(file);
  auto* out = static_cast<unsigned char*>(buffer);
  if (addr == HADDR_UNDEF || addr + size < addr || !pread_all(f->fd, out, size, addr)) return -1;
  const auto read = [f](unsigned char* to, std::size_t n, std::uint64_t at) { return pread_all(f->fd, to, n, at); };
  if ((type == H5FD_MEM_GHEAP || type == H5FD_MEM_DRAW) && !global_heap_collection_is_sound(out, size, addr, f->eof, read)) {
    H5Epush2(H5E_DEFAULT, __FILE__, __func__, __LINE__, H5E_ERR_CLS, H5E_VFL, H5E_READERROR,
             "global heap collection at %llu: an object runs past the collection (a damaged file)",
             static_cast<unsigned long long>(addr));
    return -1;
  }
  return 0;
}

herr_t c_write(H5FD_t*, H5FD_mem_t, hid_t, haddr_t, size_t, const void*) { return -1; }  // read-only
herr_t c_lock(H5FD_t*, hbool_t) { return 0; }  // readers take no lock (FORMAT.md, "Crash safety")
herr_t c_unlock(H5FD_t*) { return 0; }

H5FD_class_t make_class() {
  H5FD_class_t c;
  std::memset(&c, 0, sizeof(c));
  c.name = "kscheckedread";
  c.maxaddr = static_cast<haddr_t>(1) << 62;
  c.fc_degree = H5F_CLOSE_WEAK;
  c.open = c_open;
  c.close = c_close;
  c.cmp = c_cmp;
  c.query = c_query;
  c.get_eoa = c_get_eoa;
  c.set_eoa = c_set_eoa;
  c.get_eof = c_get_eof;
  c.get_handle = c_get_handle;
  c.read = c_read;
  c.write = c_write;
  c.lock = c_lock;
  c.unlock = c_unlock;
  H5FD_mem_t map[H5FD_MEM_NTYPES] = H5FD_FLMAP_DICHOTOMY;
  std::memcpy(c.fl_map, map, sizeof(map));
  return c;
}

const H5FD_class_t g_class = make_class();

hid_t checked_read_driver_id() {
  static std::mutex m;
  static hid_t id = -1;
  std::lock_guard<std::mutex> lk(m);
  if (id < 0 || H5Iis_valid(id) <= 0) id = H5FDregister(&g_class);
  return id;
}

}  // namespace

hid_t make_checked_read_fapl() {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (fapl < 0) return fapl;
  if (H5Pset_driver(fapl, checked_read_driver_id(), nullptr) < 0) {
    H5Pclose(fapl);
    return -1;
  }
  return fapl;
}

void check_vlen_references(hid_t dset, hid_t file_space, const std::string& path, const std::string& what) {
  const haddr_t offset = H5Dget_offset(dset);  // contiguous, allocated datasets only
  if (offset == HADDR_UNDEF) return;
  struct stat st{};
  if (::stat((path + ".journal").c_str(), &st) == 0) return;  // bytes under a journal: maybe not the committed state
  Hid space(file_space == H5S_ALL ? H5Dget_space(dset) : H5Scopy(file_space));
  if (!space.ok()) return;
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank > 1) return;
  hsize_t first = 0, last = 0;
  if (rank == 1) {
    if (H5Sget_select_npoints(space) <= 0) return;
    if (file_space == H5S_ALL) H5Sselect_all(space);
    if (H5Sget_select_bounds(space, &first, &last) < 0) return;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  if (::fstat(fd, &st) != 0) return;
  const std::uint64_t eof = static_cast<std::uint64_t>(st.st_size);
  // Each element on disk: the string's length (4 bytes), its collection's address (8) and the object's
  // index in it (4) (HDF5 file format specification, "Variable-length data").
  constexpr std::uint64_t kRef = 16;
  const std::uint64_t count = last - first + 1, at = offset + first * kRef;
  std::vector<unsigned char> refs(static_cast<std::size_t>(count * kRef));
  if (at > eof || count * kRef > eof - at || !pread_all(fd, refs.data(), refs.size(), at))
    throw StoreError(path, what + ": its variable-length strings lie past the end of the file (a damaged file)");
  std::map<std::uint64_t, std::map<std::uint64_t, std::uint64_t>> collections;
  for (std::uint64_t i = 0; i < count; ++i) {
    const unsigned char* r = refs.data() + i * kRef;
    const std::uint64_t length = le(r, 4), heap = le(r + 4, 8), index = le(r + 12, 4);
    if (heap == 0) continue;  // no string stored (HDF5 reads nothing)
    auto c = collections.find(heap);
    if (c == collections.end()) c = collections.emplace(heap, collection_objects(fd, heap, eof)).first;
    const auto o = c->second.find(index);
    if (o == c->second.end() || o->second != length)
      throw StoreError(path, what + ": the string of element " + std::to_string(first + i) +
                                 " points to no object of its length in the file's global heap (a damaged file)");
  }
}

}  // namespace ks::store::detail
