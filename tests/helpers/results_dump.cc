// talus — test helper: datasets of an HDF5 file (a results file) as one CSV
// table, for the python checkers (no h5py on the machines).
//   results_dump FILE OUT.csv [--attributes] NAME...
// Every NAME is a dataset with the same number of rows; a dataset of c > 1
// columns gives the CSV columns NAME[0] ... NAME[c-1]. Values printed with 17
// significant digits. --attributes: the integer attributes 'steps', 'probes',
// 'material points' and the string 'integration' as a first line '# k=v;...'.
// Exit 1 (with a message) if a dataset is missing or the row counts differ.
#include <talus/io/hdf5.h>

#include <mpi.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

int
main(int argc, char **argv)
{
  MPI_Init(&argc, &argv);
  int rc = 0;
  try
    {
      if (argc < 4)
        throw std::runtime_error("usage: results_dump FILE OUT.csv [--attributes] NAME...");
      talus::io::H5File                f(argv[1], talus::io::H5File::Mode::read, MPI_COMM_SELF);
      std::ofstream                    out(argv[2]);
      std::vector<std::string>         header;
      std::vector<std::vector<double>> data;
      std::vector<unsigned int>        cols;
      std::uint64_t                    rows  = 0;
      bool                             first = true;
      for (int i = 3; i < argc; ++i)
        {
          const std::string name = argv[i];
          if (name == "--attributes")
            {
              out << "# steps=" << f.get_int("steps") << ";probes=" << f.get_int("probes")
                  << ";material points=" << f.get_int("material points")
                  << ";integration=" << f.get_string("integration") << "\n";
              continue;
            }
          if (!f.exists(name))
            throw std::runtime_error("no dataset '" + name + "' in " + argv[1]);
          const auto shape = f.shape(name);
          if (!first && shape.first != rows)
            throw std::runtime_error("dataset '" + name + "' has " + std::to_string(shape.first) + " rows, not " +
                                     std::to_string(rows));
          first = false;
          rows  = shape.first;
          data.push_back(f.read_all(name));
          cols.push_back(shape.second);
          for (unsigned int c = 0; c < shape.second; ++c)
            header.push_back(shape.second > 1 ? name + "[" + std::to_string(c) + "]" : name);
        }
      for (std::size_t k = 0; k < header.size(); ++k)
        out << header[k] << (k + 1 < header.size() ? "," : "\n");
      char buf[64];
      for (std::uint64_t r = 0; r < rows; ++r)
        for (std::size_t k = 0, col = 0; k < data.size(); ++k)
          for (unsigned int c = 0; c < cols[k]; ++c, ++col)
            {
              std::snprintf(buf, sizeof buf, "%.17g", data[k][r * cols[k] + c]);
              out << buf << (col + 1 < header.size() ? "," : "\n");
            }
    }
  catch (const std::exception &e)
    {
      std::cerr << "results_dump: " << e.what() << std::endl;
      rc = 1;
    }
  MPI_Finalize();
  return rc;
}
