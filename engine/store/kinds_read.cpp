// The /kinds group of a results file, as StoreMeta::kinds (see reader_impl.hpp, FORMAT.md).
#include "store/h5util.hpp"
#include "store/reader_impl.hpp"

namespace ks::store {
using namespace detail;

namespace {
herr_t collect_link(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}
herr_t collect_attr(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}
}  // namespace

std::vector<KindMeta> read_kind_meta(hid_t file, const std::string& path) {
  std::vector<KindMeta> out;
  if (!link_exists(file, "kinds")) return out;
  Hid root(check(H5Gopen2(file, "kinds", H5P_DEFAULT), path, "open /kinds"));
  std::vector<std::string> names;
  H5Literate(root, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_link, &names);
  for (const std::string& name : names) {
    Hid g(check(H5Gopen2(root, name.c_str(), H5P_DEFAULT), path, "open /kinds/" + name));
    std::vector<std::string> attrs;
    H5Aiterate2(g, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_attr, &attrs);
    KindMeta k;
    k.name = name;
    for (const std::string& a : attrs) k.lists.emplace_back(a, read_str_list_attr(g, a.c_str()));
    out.push_back(std::move(k));
  }
  return out;
}

}  // namespace ks::store
