! A VFRICTION-style friction routine that asks mufric for mu once per block of contact nodes, as
! seed 001's Listing 1 does with its closed-form law: pressure = fNormal/areaCont, slip rate =
! |dSlip|/dt, fTangential = -min(mu*fn, fStickForce). It uses only the F77 entry points of the C
! ABI (no modules), so it drops into an Abaqus/Explicit user subroutine file.
!
! Units: this example assumes a model in mm-N-s (common for machining); mufric wants SI, hence the
! two conversion factors. A meso model already in SI sets both to 1.
      subroutine vfriction_mufric(handle, nBlock, fNormal, areaCont, dSlip, dtime, fibreAngle, &
                                  fStickForce, fTangential, mu, ierr)
      implicit none
      integer*8 handle
      integer nBlock, ierr
      real*8 fNormal(nBlock), areaCont(nBlock), dSlip(2, nBlock), dtime, fibreAngle
      real*8 fStickForce(nBlock), fTangential(2, nBlock), mu(nBlock)
      real*8 pressure(nBlock), velocity(nBlock), temperature(nBlock), angle(nBlock), slip
      real*8, parameter :: toPascal = 1.0d6           ! N/mm^2 -> Pa
      real*8, parameter :: toMetrePerSecond = 1.0d-3  ! mm/s -> m/s
      integer k

      do k = 1, nBlock
        slip = sqrt(dSlip(1, k)**2 + dSlip(2, k)**2)
        pressure(k) = 0.0d0
        velocity(k) = 0.0d0
        if (areaCont(k) /= 0.0d0) pressure(k) = toPascal * fNormal(k) / areaCont(k)
        if (dtime /= 0.0d0) velocity(k) = toMetrePerSecond * slip / dtime
        temperature(k) = 293.15d0   ! not used by the seed-001 law; a GP in (p, v, T) would need it
        angle(k) = fibreAngle
      end do
      call mufric_evaluate(handle, nBlock, pressure, velocity, temperature, angle, mu, ierr)
      if (ierr /= 0) return
      do k = 1, nBlock
        fTangential(2, k) = 0.0d0
        if (fNormal(k) /= 0.0d0 .and. dtime /= 0.0d0 .and. dSlip(1, k) /= 0.0d0) then
          fTangential(1, k) = -min(mu(k) * fNormal(k), fStickForce(k))
        else
          mu(k) = 0.0d0                ! no contact: no friction (Listing 1)
          fTangential(1, k) = 0.0d0
        end if
      end do
      end subroutine

! Driver: one block of five nodes against seed 001's Table 4 law at 90 deg, checked against the
! closed form mu = clamp(0.149911 + 0.013133 v[m/min] - 0.000753 p[MPa], 0.093755565, 0.322395506).
      program vfriction_example
      implicit none
      integer, parameter :: n = 5
      integer*8 handle
      integer ierr, k, failures
      character(len=512) uri
      real*8 fNormal(n), areaCont(n), dSlip(2, n), fStick(n), fTan(2, n), mu(n), expected, pMpa, vMmin
      real*8, parameter :: dtime = 1.0d-6, pi = 3.14159265358979d0

      call get_command_argument(1, uri)
      call mufric_open(uri, handle, ierr)
      if (ierr /= 0) then
        print *, 'mufric_open failed with status', ierr
        stop 2
      end if
      fNormal  = [10.0d0, 40.0d0, 5.0d0, 0.0d0, 20.0d0]      ! N
      areaCont = [0.2d0, 0.25d0, 0.1d0, 0.1d0, 0.5d0]        ! mm^2 -> 50, 160, 50, 0, 40 MPa
      dSlip(1, :) = [1.0d-4, 2.0d-4, 5.0d-5, 1.0d-4, 2.5d-4] ! mm in dtime -> 6, 12, 3, 6, 15 m/min
      dSlip(2, :) = 0.0d0
      fStick = [100.0d0, 100.0d0, 100.0d0, 100.0d0, 1.0d0]
      call vfriction_mufric(handle, n, fNormal, areaCont, dSlip, dtime, pi / 2, fStick, fTan, mu, ierr)
      if (ierr /= 0) then
        print *, 'mufric_evaluate failed with status', ierr
        stop 2
      end if
      failures = 0
      do k = 1, n
        pMpa = fNormal(k) / areaCont(k)
        vMmin = dSlip(1, k) / dtime * 1.0d-3 * 60.0d0
        expected = min(max(0.149911d0 + 0.013133d0 * vMmin - 0.000753d0 * pMpa, 0.093755565d0), 0.322395506d0)
        if (fNormal(k) == 0.0d0) expected = 0.0d0
        print '(a, i2, a, f9.3, a, f8.3, a, f9.6, a, f10.5)', 'node', k, '  p[MPa]', pMpa, '  v[m/min]', vMmin, &
              '  mu', mu(k), '  fT[N]', fTan(1, k)
        if (abs(mu(k) - expected) > 1.0d-9) failures = failures + 1
        if (abs(fTan(1, k) + min(expected * fNormal(k), fStick(k))) > 1.0d-9) failures = failures + 1
      end do
      call mufric_close(handle)
      if (failures > 0) then
        print *, failures, 'mismatches against the closed-form law'
        stop 1
      end if
      print *, 'all nodes match the closed-form law'
      end program
