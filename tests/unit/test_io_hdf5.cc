// Parallel HDF5 tables: rows written by each rank (one rank with none) come
// back in rank order on any number of readers; attributes round-trip; the file
// appears only on commit; a missing dataset is a clear InputError.
#include <talus/base/errors.h>
#include <talus/io/hdf5.h>

#include <gtest/gtest.h>

#include <filesystem>

using talus::io::H5File;

namespace
{
  int
  rank()
  {
    int r;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
  }
  int
  size()
  {
    int s;
    MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
  }
} // namespace

TEST(HDF5, RowsInRankOrderAndAttributes)
{
  const std::string path = "test_io_hdf5_" + std::to_string(size()) + ".h5";
  if (rank() == 0)
    std::filesystem::remove(path);
  MPI_Barrier(MPI_COMM_WORLD);
  // rank r writes r*3 rows (rank 0 none) of 2 columns: (global row, r)
  std::uint64_t first = 0;
  for (int r = 0; r < rank(); ++r)
    first += 3 * r;
  std::vector<double>        rows;
  std::vector<std::uint64_t> ids;
  for (int i = 0; i < 3 * rank(); ++i)
    {
      rows.push_back(static_cast<double>(first + i));
      rows.push_back(rank() + 0.5);
      ids.push_back(1000 + first + i);
    }
  {
    H5File f(path, H5File::Mode::create, MPI_COMM_WORLD);
    f.write_rows("particles/data", rows, 2);
    f.write_rows("particles/id", ids, 1);
    f.write_global("series", {1.0, 2.0, 3.0}, 3);
    f.set_attribute("time", 0.125);
    f.set_attribute("step", std::int64_t(42));
    f.set_attribute("format", std::string("talus-test"));
    EXPECT_FALSE(std::filesystem::exists(path));
    f.commit();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".part"));

  H5File        f(path, H5File::Mode::read, MPI_COMM_WORLD);
  std::uint64_t total = 0;
  for (int r = 0; r < size(); ++r)
    total += 3 * r;
  const auto shape = f.shape("particles/data");
  EXPECT_EQ(shape.first, total);
  EXPECT_EQ(shape.second, 2u);
  const auto all = f.read_all("particles/data");
  for (std::uint64_t i = 0; i < total; ++i)
    EXPECT_EQ(all[2 * i], static_cast<double>(i));
  const auto [b, e] = talus::io::block_range(total, rank(), size());
  const auto part   = f.read_rows_u64("particles/id", b, e);
  ASSERT_EQ(part.size(), e - b);
  for (std::uint64_t i = b; i < e; ++i)
    EXPECT_EQ(part[i - b], 1000 + i);
  EXPECT_EQ(f.read_all("series").size(), 3u);
  EXPECT_DOUBLE_EQ(f.get_double("time"), 0.125);
  EXPECT_EQ(f.get_int("step"), 42);
  EXPECT_EQ(f.get_string("format"), "talus-test");
  EXPECT_THROW(f.shape("nothing/here"), talus::InputError);
  EXPECT_THROW(f.get_double("nothing"), talus::InputError);
}

TEST(HDF5, MissingFileIsInputError)
{
  EXPECT_THROW(H5File("no-such-file.h5", H5File::Mode::read, MPI_COMM_WORLD), talus::InputError);
}

TEST(HDF5, BlockRangeCoversAll)
{
  for (unsigned n : {0u, 1u, 7u, 100u})
    for (unsigned p : {1u, 2u, 3u, 8u})
      {
        std::uint64_t next = 0;
        for (unsigned r = 0; r < p; ++r)
          {
            const auto [b, e] = talus::io::block_range(n, r, p);
            EXPECT_EQ(b, next);
            next = e;
          }
        EXPECT_EQ(next, n);
      }
}
